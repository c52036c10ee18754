#include "raytrace/render/surface.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "raytrace/traverse/traversal_shared.h"

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

}  // namespace sinew::rt
