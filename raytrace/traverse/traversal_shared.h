// Pieces every traversal width shares beside traverse/ray_frames.h
// (private to raytrace/: traverse/, cull/ and render/ use them): magnitudes,
// ray validity, the small static meshes tested directly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/ray_frames.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"

namespace sinew::rt::detail {

inline float max_abs(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }
inline float max_abs(const Aabb& box) { return std::max(max_abs(box.lower), max_abs(box.upper)); }

// Rays the queries accept (traverse/ray_frames.h valid_rays, one lane).
inline bool valid_ray(const Ray& ray) {
  return per_lane::valid_rays<float>(ray.origin, ray.direction, ray.t_min, ray.t_max);
}

// Static meshes with at most this many triangles (a ground quad, a wall)
// are tested triangle by triangle, without walking their kd-tree: the walk
// costs more than the tests, and testing every triangle gives the same
// nearest hit. Single rays and packets both do it, so they stay alike.
inline constexpr std::size_t kBruteForceStaticTriangles = 8;

// Whether a top-level object is such a static mesh.
inline bool is_small_static(const Scene& scene, const TopLevelObject& object) {
  return object.kind == TopLevelObject::Kind::kStatic &&
         scene.static_meshes()[object.index].desc.triangles.size() <= kBruteForceStaticTriangles;
}

// Whether the short cut for such meshes applies to `objects` (indices into
// the top level): the fast test, and every object a small static mesh.
inline bool small_statics_only(const Scene& scene, TriangleTest test, std::span<const std::uint32_t> objects) {
  if (test != TriangleTest::kFast) return false;
  const std::span<const TopLevelObject> all = scene.top_level().objects();
  return std::all_of(objects.begin(), objects.end(),
                     [&](std::uint32_t object) { return is_small_static(scene, all[object]); });
}

}  // namespace sinew::rt::detail
