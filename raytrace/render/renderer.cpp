#include "raytrace/render/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "raytrace/render/output_planes.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/render/tile_stages.h"
#include "raytrace/render/traversal_shared.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {
namespace {

// pbrt's gamma(n): a bound on n successive float roundings.
constexpr float gamma(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (static_cast<float>(n) * u) / (1.0f - static_cast<float>(n) * u);
}

// The next float towards +inf (up) or -inf; infinities and NaN unchanged.
float next_float(float x, bool up) {
  if (!std::isfinite(x)) return x;
  if (x == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
  std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  bits = (x > 0.0f) == up ? bits + 1 : bits - 1;
  return std::bit_cast<float>(bits);
}

// Sums per-tile counters in tile order so the totals are deterministic.
void add(TraversalCounters& into, const TraversalCounters& from) {
  into.rays += from.rays;
  into.node_visits += from.node_visits;
  into.object_visits += from.object_visits;
  into.triangle_tests += from.triangle_tests;
}

}  // namespace

SurfacePoint surface_at(const Scene& scene, const Hit& hit, const Vec3& default_albedo) {
  SurfacePoint s;
  const Scene::ObjectSlot slot = scene.object_slots()[hit.instance_id];
  const float w = 1.0f - hit.u - hit.v;
  Vec3 p[3];
  Vec3 shading(0.0f);
  bool have_normals = false;
  if (slot.kind == Scene::ObjectKind::kCharacter) {
    const InstanceFrame& frame = scene.instances()[slot.index];
    const SkinnedMesh& mesh = *scene.characters()[frame.character].mesh;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int i = 0; i < 3; ++i) p[i] = frame.positions[v[static_cast<std::size_t>(i)]];
    if (!frame.normals.empty()) {
      shading = w * frame.normals[v[0]] + hit.u * frame.normals[v[1]] + hit.v * frame.normals[v[2]];
      have_normals = true;
    }
    s.albedo = default_albedo;
    if (hit.triangle_id < mesh.triangle_material.size()) {
      const std::uint32_t m = mesh.triangle_material[hit.triangle_id];
      if (m < mesh.material_colors.size()) s.albedo = mesh.material_colors[m];
    }
  } else {
    const StaticMeshDesc& mesh = scene.static_meshes()[slot.index].desc;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int i = 0; i < 3; ++i) p[i] = mesh.positions[v[static_cast<std::size_t>(i)]];
    s.albedo = default_albedo;
    const std::uint32_t m = mesh.triangle_material.empty() ? 0 : mesh.triangle_material[hit.triangle_id];
    if (m < mesh.material_colors.size()) s.albedo = mesh.material_colors[m];
  }
  s.position = w * p[0] + hit.u * p[1] + hit.v * p[2];
  // Bounds the rounding of `position` and, more to the point, of a triangle
  // test started from it: Moller-Trumbore forms origin - p0 in every axis,
  // so its error is relative to the largest vertex coordinate in any axis.
  // A per-axis bound is 0 across a floor at exactly y = 0, and a shadow ray
  // started one float above it hit the floor itself at t = -0.
  const float magnitude = std::max({detail::max_abs(p[0]), detail::max_abs(p[1]), detail::max_abs(p[2])});
  s.error = Vec3(gamma(7) * magnitude);
  const Vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
  const float length = glm::length(n);
  s.geometric_normal = length > 0.0f && std::isfinite(length) ? n / length : Vec3(0.0f, 0.0f, 1.0f);
  const float shading_length = have_normals ? glm::length(shading) : 0.0f;
  s.shading_normal = shading_length > 0.0f && std::isfinite(shading_length) ? shading / shading_length
                                                                             : s.geometric_normal;
  return s;
}

Vec3 offset_origin(const SurfacePoint& surface, const Vec3& toward) {
  const Vec3& n = surface.geometric_normal;
  const float distance = glm::dot(glm::abs(n), surface.error);
  Vec3 offset = distance * n;
  if (glm::dot(n, toward) < 0.0f) offset = -offset;
  Vec3 origin = surface.position + offset;
  // The addition itself rounds: step one more float away from the surface.
  for (int a = 0; a < 3; ++a) {
    if (offset[a] > 0.0f) origin[a] = next_float(origin[a], true);
    if (offset[a] < 0.0f) origin[a] = next_float(origin[a], false);
  }
  return origin;
}

Ray shadow_ray_from_light(const SurfacePoint& surface, const Vec3& toward, const Vec3& light) {
  SurfacePoint widened = surface;
  const float reach = detail::max_abs(light) + 2.0f * detail::max_abs(light - surface.position);
  widened.error = surface.error + Vec3(gamma(32) * reach);
  Ray ray;
  ray.origin = light;
  ray.direction = offset_origin(widened, toward) - light;
  ray.t_min = 0.0f;
  ray.t_max = 1.0f;
  return ray;
}

namespace {

using Clock = std::chrono::steady_clock;

double nanoseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::nano>(to - from).count();
}

// Per tile: time spent in each phase and what it counted.
struct TileRecord {
  TraversalCounters primary;
  TraversalCounters shadow;
  std::uint64_t hits = 0;
  std::uint64_t shadowed = 0;
  double primary_ns = 0.0;
  double shadow_ns = 0.0;
  double shade_ns = 0.0;
};

Expected<OutputPlanes> output_planes(const FrameBuffers& buffers) {
  const int w = buffers.width;
  const int h = buffers.height;
  const FrameBuffers::RowPitches& pitch = buffers.row_pitch;
  OutputPlanes out;
  SINEW_ASSIGN_OR_RETURN(out.rgba8,
                         output_plane(buffers.color_rgba8, pitch.color_rgba8, 4, w, h, "buffers.color_rgba8"));
  SINEW_ASSIGN_OR_RETURN(out.rgba32f,
                         output_plane(buffers.color_rgba32f, pitch.color_rgba32f, 4, w, h, "buffers.color_rgba32f"));
  SINEW_ASSIGN_OR_RETURN(out.depth, output_plane(buffers.depth, pitch.depth, 1, w, h, "buffers.depth"));
  SINEW_ASSIGN_OR_RETURN(out.normal, output_plane(buffers.normal, pitch.normal, 1, w, h, "buffers.normal"));
  SINEW_ASSIGN_OR_RETURN(out.triangle,
                         output_plane(buffers.triangle_id, pitch.triangle_id, 1, w, h, "buffers.triangle_id"));
  SINEW_ASSIGN_OR_RETURN(out.instance,
                         output_plane(buffers.instance_id, pitch.instance_id, 1, w, h, "buffers.instance_id"));
  return out;
}

}  // namespace

bool characters_look_fine(const Scene& scene, const PinholeCamera& camera) {
  // Pixels per unit of image-plane slope, along the image's x and y.
  const float w = static_cast<float>(camera.width()), h = static_cast<float>(camera.height());
  const float across = w / (camera.right_offset(w) - camera.right_offset(0.0f));
  const float down = h / (camera.up_offset(0.0f) - camera.up_offset(h));
  for (const InstanceFrame& frame : scene.instances()) {
    Aabb box = Aabb::empty();
    for (const Aabb& b : frame.bone_world_boxes) box.extend(b);
    if (!(box.lower.x <= box.upper.x)) continue;
    float x_lo = std::numeric_limits<float>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
    bool in_front = true;
    for (int corner = 0; corner < 8 && in_front; ++corner) {
      const Vec3 p((corner & 1) ? box.upper.x : box.lower.x, (corner & 2) ? box.upper.y : box.lower.y,
                   (corner & 4) ? box.upper.z : box.lower.z);
      const Vec3 q = p - camera.eye();
      const float z = glm::dot(q, camera.forward());
      in_front = z > 0.0f;
      const float x = glm::dot(q, camera.right()) / z, y = glm::dot(q, camera.up()) / z;
      x_lo = std::min(x_lo, x);
      x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y);
      y_hi = std::max(y_hi, y);
    }
    const std::size_t triangles = scene.characters()[frame.character].mesh->triangles.size();
    if (!in_front || triangles == 0) continue;
    const double pixels = static_cast<double>((x_hi - x_lo) * across) * static_cast<double>((y_hi - y_lo) * down);
    if (pixels <= kFineBoxPixelsPerTriangle * static_cast<double>(triangles)) return true;
  }
  return false;
}

namespace {

// One tile, stage by stage (render/tile_stages.h), timing each phase.
void render_tile(const Scene& scene, const PinholeCamera& camera, const RenderSettings& settings,
                 std::span<const Light> lights, bool characters_fine, bool fine, const OutputPlanes& out,
                 const Tile& tile, TileRecord& record) {
  TileScratch& s = tile_scratch();
  int region_x = 1, region_y = 1;
  packet_region_blocks(settings.packet_rays, region_x, region_y);
  s.prepare(tile, region_x, region_y);
  s.split_fine_shadows = settings.split_fine_shadow_packets;
  s.split_static_shadows = fine;
  s.shadow_group_frusta = fine;
  s.clip_leaf_lanes = characters_fine;
  const auto t0 = Clock::now();
  generate_camera_rays(camera, s);
  trace_primary(scene, camera, settings.triangle_test, settings.packet_rays, s, record.primary);
  const auto t1 = Clock::now();
  for (std::size_t b = 0; b < s.lanes / kBlockLanes; ++b) {
    record.hits += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(s.block_hits[b])));
  }
  std::fill(s.lit.begin(), s.lit.begin() + static_cast<std::ptrdiff_t>(s.lanes),
            static_cast<std::uint8_t>((1u << lights.size()) - 1u));
  if (out.want_surface()) reconstruct_surfaces(scene, settings.default_albedo, s);
  double shadow_ns = 0.0;
  if (out.want_color() && settings.shadows) {
    const auto shadow_start = Clock::now();
    for (std::size_t l = 0; l < lights.size(); ++l) {
      aim_shadow_rays(lights[l], static_cast<int>(l), s);
      record.shadowed +=
          trace_shadow_rays(scene, settings.triangle_test, settings.packet_rays, static_cast<int>(l), s,
                            record.shadow);
    }
    shadow_ns = nanoseconds(shadow_start, Clock::now());
  }
  shade_and_write(settings, lights, out, s);
  const auto t3 = Clock::now();
  record.primary_ns = nanoseconds(t0, t1);
  record.shadow_ns = shadow_ns;
  record.shade_ns = nanoseconds(t1, t3) - shadow_ns;
}

}  // namespace

Expected<RenderStats> Renderer::render(const Scene& scene, const PinholeCamera& camera,
                                       const RenderSettings& settings, const FrameBuffers& buffers,
                                       JobSystem& jobs, PhaseTimers* timers) {
  if (buffers.width != camera.width() || buffers.height != camera.height()) {
    return invalid_argument("buffers.width x height",
                            std::to_string(buffers.width) + "x" + std::to_string(buffers.height),
                            "differs from the camera's image size");
  }
  if (!valid_packet_rays(settings.packet_rays)) {
    return invalid_argument("settings.packet_rays", std::to_string(settings.packet_rays), "must be 1, 8, 64 or 256");
  }
  if (settings.tile_size < 1) {
    return invalid_argument("settings.tile_size", std::to_string(settings.tile_size), "must be at least 1");
  }
  const std::span<const Light> lights =
      settings.lights.empty() ? std::span<const Light>(&settings.light, 1) : settings.lights;
  if (lights.size() > kMaxLights) {
    return invalid_argument("settings.lights", std::to_string(lights.size()),
                            "at most " + std::to_string(kMaxLights) + " lights");
  }
  SINEW_ASSIGN_OR_RETURN(const OutputPlanes out, output_planes(buffers));
  const int tile = settings.tile_size;
  const int tiles_x = (buffers.width + tile - 1) / tile;
  const int tiles_y = (buffers.height + tile - 1) / tile;
  std::vector<TileRecord> records(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));

  const auto start = Clock::now();
  const bool characters_fine = characters_look_fine(scene, camera);
  const bool fine = settings.shadows && settings.split_fine_shadow_packets && characters_fine;
  jobs.parallel_for_tiles(buffers.width, buffers.height, tile, [&](const Tile& t) {
    render_tile(scene, camera, settings, lights, characters_fine, fine, out, t,
                records[static_cast<std::size_t>(t.index)]);
  });
  const double wall_ms = ms_since(start);

  // Tile order keeps the sums deterministic.
  RenderStats stats;
  double primary_ns = 0.0, shadow_ns = 0.0, shade_ns = 0.0;
  for (const TileRecord& r : records) {
    add(stats.primary, r.primary);
    add(stats.shadow, r.shadow);
    stats.primary_hits += r.hits;
    stats.shadowed += r.shadowed;
    primary_ns += r.primary_ns;
    shadow_ns += r.shadow_ns;
    shade_ns += r.shade_ns;
  }
  stats.primary_rays = static_cast<std::uint64_t>(buffers.width) * static_cast<std::uint64_t>(buffers.height);
  stats.shadow_rays = stats.shadow.rays;
  // The phases interleave within each tile: the wall time of the whole
  // render is split in proportion to the time the tiles spent in each.
  const double busy_ns = primary_ns + shadow_ns + shade_ns;
  if (busy_ns > 0.0) {
    stats.trace_primary_ms = wall_ms * primary_ns / busy_ns;
    stats.trace_shadow_ms = wall_ms * shadow_ns / busy_ns;
    stats.shade_ms = wall_ms * shade_ns / busy_ns;
  } else {
    stats.shade_ms = wall_ms;
  }

  if (timers) {
    timers->record("trace primary", stats.trace_primary_ms);
    timers->record("trace shadow", stats.trace_shadow_ms);
    timers->record("shade", stats.shade_ms);
  }
  return stats;
}

}  // namespace sinew::rt
