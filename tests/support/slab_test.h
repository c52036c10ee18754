// Whether a ray's points o + t d, t in [t0, t1], meet a box: the slab test
// in double precision, the independent reference the culling tests hold
// every cull to (a cull may drop a box only when this says no ray enters).
#pragma once

#include <algorithm>
#include <utility>

#include "runtime/math/aabb.h"
#include "runtime/math/types.h"

namespace sinew::testing_support {

// The ray's passage through the box: [t0, t1] clipped to it, in double
// precision; empty (first > second) where the ray misses it.
inline std::pair<double, double> ray_box_passage(const Vec3& o, const Vec3& d, double t0, double t1,
                                                 const Aabb& box) {
  for (int a = 0; a < 3; ++a) {
    const double oa = o[a], da = d[a], lo = box.lower[a], hi = box.upper[a];
    if (da == 0.0) {
      if (oa < lo || oa > hi) return {1.0, 0.0};
      continue;
    }
    const double n = (lo - oa) / da, f = (hi - oa) / da;
    t0 = std::max(t0, std::min(n, f));
    t1 = std::min(t1, std::max(n, f));
  }
  return {t0, t1};
}

inline bool ray_enters_box(const Vec3& o, const Vec3& d, double t0, double t1, const Aabb& box) {
  const auto [enter, leave] = ray_box_passage(o, d, t0, t1, box);
  return enter <= leave;
}

}  // namespace sinew::testing_support
