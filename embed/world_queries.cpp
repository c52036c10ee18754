// sinew::api::World's ray queries: single rays through rt::intersect and
// rt::occluded (traverse/traversal.h) with the ray's mask on the scene's
// frame state, prepared again first when an instance changed since the last
// pass or query; each hit completed with its normal, UV and material.
#include <cmath>
#include <string>

#include "embed/api_errors.h"
#include "embed/convert.h"
#include "embed/world_impl.h"
#include "raytrace/traverse/traversal.h"

namespace sinew::api {
namespace {

rt::TriangleTest to_internal(TriangleTest test) {
  return test == TriangleTest::kWatertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast;
}

bool finite(const Float3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What is wrong with `ray`, or empty.
std::string ray_problem(const Ray& ray) {
  if (!finite(ray.origin)) return "origin is not finite";
  if (!finite(ray.direction)) return "direction is not finite";
  if (ray.direction.x == 0.0f && ray.direction.y == 0.0f && ray.direction.z == 0.0f) return "direction is zero";
  if (!(ray.t_min >= 0.0f) || !std::isfinite(ray.t_min)) {
    return "t_min = " + std::to_string(ray.t_min) + ": expected a finite t >= 0";
  }
  if (!(ray.t_max >= ray.t_min)) return "t_max = " + std::to_string(ray.t_max) + ": expected t_max >= t_min";
  return {};
}

Status check_rays(const char* call, std::span<const Ray> rays) {
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const std::string problem = ray_problem(rays[i]);
    if (!problem.empty()) {
      return detail::api_error(ErrorCode::kInvalidArgument,
                               std::string(call) + ": rays[" + std::to_string(i) + "]: " + problem);
    }
  }
  return Status();
}

sinew::Ray to_internal(const Ray& ray) {
  sinew::Ray r;
  r.origin = detail::to_internal(ray.origin);
  r.direction = detail::to_internal(ray.direction);
  r.t_min = ray.t_min;
  r.t_max = ray.t_max;
  return r;
}

// The hit with what a host shades or filters by: the posed triangle's
// geometric normal (its winding's side, computed in double so a thin
// triangle keeps its direction), the mesh's UVs interpolated with the
// barycentrics, and the triangle's material.
RayHit to_api(const rt::Scene& scene, const Hit& hit) {
  RayHit h;
  if (!hit.valid()) return h;
  h.t = hit.t;
  h.u = hit.u;
  h.v = hit.v;
  h.instance = hit.instance_id;
  h.triangle = hit.triangle_id;
  const rt::Scene::ObjectSlot slot = scene.object_slots()[hit.instance_id];
  const Vec3* corners[3];
  if (slot.kind == rt::Scene::ObjectKind::kCharacter) {
    const rt::InstanceFrame& frame = scene.instances()[slot.index];
    const SkinnedMesh& mesh = *scene.characters()[frame.character].mesh;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int c = 0; c < 3; ++c) corners[c] = &frame.positions[v[static_cast<std::size_t>(c)]];
    if (mesh.uvs.size() == mesh.positions.size()) {
      const float w = 1.0f - hit.u - hit.v;
      const Vec2 uv = w * mesh.uvs[v[0]] + hit.u * mesh.uvs[v[1]] + hit.v * mesh.uvs[v[2]];
      h.uv = {uv.x, uv.y};
    }
    h.material = hit.triangle_id < mesh.triangle_material.size() ? mesh.triangle_material[hit.triangle_id] : kNoHit;
  } else {
    const rt::StaticMeshDesc& mesh = scene.static_meshes()[slot.index].desc;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int c = 0; c < 3; ++c) corners[c] = &mesh.positions[v[static_cast<std::size_t>(c)]];
    h.material = hit.triangle_id < mesh.triangle_material.size() ? mesh.triangle_material[hit.triangle_id] : 0;
  }
  const glm::dvec3 p0(*corners[0]);
  const glm::dvec3 n = glm::cross(glm::dvec3(*corners[1]) - p0, glm::dvec3(*corners[2]) - p0);
  const double length = glm::length(n);
  // A hit has a nonzero determinant, so a nonzero cross product; zero
  // stays zero rather than NaN all the same.
  if (length > 0.0 && std::isfinite(length)) {
    h.geometric_normal = {static_cast<float>(n.x / length), static_cast<float>(n.y / length),
                          static_cast<float>(n.z / length)};
  }
  return h;
}

// The scene's frame state for the world as posed now, escaped triangles
// routed: prepared again unless the last pass or query left exactly that. A
// batch prepares only the instances its rays can reach (lazy skinning), a
// single ray every instance, which the queries after it reuse.
Status prepare_for_queries(World::Impl& world, std::span<const Ray> rays) {
  if (world.prepared_changes == world.changes && world.prepared_exact) return Status();
  if (!world.query_jobs) world.query_jobs = std::make_unique<JobSystem>(1);
  rt::FrameOptions options;
  options.normals = false;  // queries read positions only; a pass prepares its own frame
  options.fallback = true;
  world.query_rays.clear();
  if (rays.size() > 1 && world.lazy_query_skinning) {
    for (const Ray& ray : rays) world.query_rays.push_back(to_internal(ray));
    options.rays = world.query_rays;
  }
  world.prepared_changes = 0;
  const auto prepared = world.scene.prepare_frame(options, *world.query_jobs);
  if (!prepared.ok()) return detail::to_api_error(prepared.status());
  world.prepared_changes = world.changes;
  world.prepared_exact = prepared->culled_instances == 0;
  return Status();
}

// What every query checks before tracing: one answer slot per ray, valid
// rays, and the frame state prepared for the world as posed now.
Status ready_for(World::Impl& world, const char* call, std::span<const Ray> rays, const char* answers_name,
                 std::size_t answers) {
  if (answers != rays.size()) {
    return detail::api_error(ErrorCode::kInvalidArgument, std::string(call) + ": " + answers_name + ": " +
                                                              std::to_string(answers) + " entries for " +
                                                              std::to_string(rays.size()) + " rays");
  }
  if (Status status = check_rays(call, rays); !status.ok()) return status;
  return prepare_for_queries(world, rays);
}

}  // namespace

Result<RayHit> World::intersect(const Ray& ray, TriangleTest test) noexcept {
  return detail::guarded("World::intersect", [&]() -> Result<RayHit> {
    RayHit hit;
    const Status status = intersect(std::span<const Ray>(&ray, 1), std::span<RayHit>(&hit, 1), test);
    if (!status.ok()) return status.error();
    return hit;
  });
}

Status World::intersect(std::span<const Ray> rays, std::span<RayHit> hits, TriangleTest test) noexcept {
  return detail::guarded("World::intersect", [&]() -> Status {
    if (Status status = ready_for(*impl_, "World::intersect", rays, "hits", hits.size()); !status.ok()) {
      return status;
    }
    const rt::TriangleTest internal = to_internal(test);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      hits[i] = to_api(impl_->scene, rt::intersect(impl_->scene, to_internal(rays[i]), rays[i].mask, internal));
    }
    return Status();
  });
}

Result<bool> World::occluded(const Ray& ray, TriangleTest test) noexcept {
  return detail::guarded("World::occluded", [&]() -> Result<bool> {
    std::uint8_t blocked = 0;
    const Status status = occluded(std::span<const Ray>(&ray, 1), std::span<std::uint8_t>(&blocked, 1), test);
    if (!status.ok()) return status.error();
    return blocked != 0;
  });
}

Status World::occluded(std::span<const Ray> rays, std::span<std::uint8_t> blocked, TriangleTest test) noexcept {
  return detail::guarded("World::occluded", [&]() -> Status {
    if (Status status = ready_for(*impl_, "World::occluded", rays, "blocked", blocked.size()); !status.ok()) {
      return status;
    }
    const rt::TriangleTest internal = to_internal(test);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      blocked[i] = rt::occluded(impl_->scene, to_internal(rays[i]), rays[i].mask, internal) ? 1 : 0;
    }
    return Status();
  });
}

}  // namespace sinew::api
