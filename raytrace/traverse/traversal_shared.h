// Pieces the single-ray and the packet traversals share (private to
// raytrace/: traverse/, cull/ and render/ use them). Both must round exactly alike, lane for ray, so the
// packet's results are bit-identical to the single ray's: keeping one copy
// of these is what guarantees it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"

namespace sinew::rt::detail {

inline float max_abs(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }
inline float max_abs(const Aabb& box) { return std::max(max_abs(box.lower), max_abs(box.upper)); }

inline bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Rays the queries accept: finite, a non-zero direction, a non-empty range.
inline bool valid_ray(const Ray& ray) {
  return finite(ray.origin) && finite(ray.direction) && ray.direction != Vec3(0.0f) &&
         !std::isnan(ray.t_min) && !std::isnan(ray.t_max) && ray.t_min < ray.t_max;
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

// Clips [t0, t1] to the ray's passage through `box` grown by `eps` on every
// side. The growth absorbs the rounding of the slab arithmetic, which is
// relative to the magnitudes folded into `eps` by the callers.
inline bool clip_to_box(const Aabb& box, float eps, const Vec3& o, const Vec3& d, const Vec3& inv_d, float& t0,
                        float& t1) {
  for (int a = 0; a < 3; ++a) {
    const float lo = box.lower[a] - eps;
    const float hi = box.upper[a] + eps;
    if (d[a] == 0.0f) {
      if (!(o[a] >= lo && o[a] <= hi)) return false;
      continue;
    }
    float near = (lo - o[a]) * inv_d[a];
    float far = (hi - o[a]) * inv_d[a];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
  }
  return t0 <= t1;
}

// Per object, the triangles already tested: a triangle whose fuzzy box
// straddles splits is listed in several leaves. Direct-mapped on the low bits
// of the id, which neighbouring triangles in a leaf differ in.
class Mailbox {
 public:
  void reset() { ids_.fill(kInvalidId); }
  bool seen(std::uint32_t id) {
    std::uint32_t& slot = ids_[id & (ids_.size() - 1)];
    if (slot == id) return true;
    slot = id;
    return false;
  }

 private:
  std::array<std::uint32_t, 16> ids_{};
};

}  // namespace sinew::rt::detail
