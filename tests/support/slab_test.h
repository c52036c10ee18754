// Whether a ray's points o + t d, t in [t0, t1], meet a box: the slab test
// in double precision, the independent reference the culling tests hold
// every cull to (a cull may drop a box only when this says no ray enters).
#pragma once

#include <algorithm>

#include "runtime/math/aabb.h"
#include "runtime/math/types.h"

namespace sinew::testing_support {

inline bool ray_enters_box(const Vec3& o, const Vec3& d, double t0, double t1, const Aabb& box) {
  for (int a = 0; a < 3; ++a) {
    const double oa = o[a], da = d[a], lo = box.lower[a], hi = box.upper[a];
    if (da == 0.0) {
      if (oa < lo || oa > hi) return false;
      continue;
    }
    const double n = (lo - oa) / da, f = (hi - oa) / da;
    t0 = std::max(t0, std::min(n, f));
    t1 = std::min(t1, std::max(n, f));
  }
  return t0 <= t1;
}

}  // namespace sinew::testing_support
