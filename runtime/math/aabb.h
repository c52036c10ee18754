// Aabb: axis-aligned bounding box, the currency of fuzzy boxes (paper
// section 3.2), kd-tree cells and the per-frame top-level tree.
//
// The empty box is lower = +inf, upper = -inf, so union with it is the
// identity and no special case is needed when growing a box point by point.
#pragma once

#include <limits>

#include "runtime/math/affine.h"
#include "runtime/math/types.h"

namespace sinew {

struct Aabb {
  Vec3 lower{std::numeric_limits<float>::infinity()};
  Vec3 upper{-std::numeric_limits<float>::infinity()};

  static Aabb empty() { return {}; }
  static Aabb from_point(const Vec3& p) { return {p, p}; }
  static Aabb from_corners(const Vec3& a, const Vec3& b) { return {glm::min(a, b), glm::max(a, b)}; }

  // True when no point lies inside (any lower > upper). A box of zero width
  // (a flat triangle's box) is not empty.
  bool is_empty() const { return lower.x > upper.x || lower.y > upper.y || lower.z > upper.z; }

  void extend(const Vec3& p) {
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
  }
  void extend(const Aabb& b) {
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
  }

  Vec3 extent() const { return upper - lower; }
  Vec3 center() const { return 0.5f * (lower + upper); }

  // 2(xy + yz + zx); 0 for an empty box (the SAH treats it as free).
  float surface_area() const;

  bool contains(const Vec3& p) const {
    return p.x >= lower.x && p.x <= upper.x && p.y >= lower.y && p.y <= upper.y &&
           p.z >= lower.z && p.z <= upper.z;
  }
  bool contains(const Aabb& b) const {
    return b.is_empty() || (contains(b.lower) && contains(b.upper));
  }
};

Aabb merge(const Aabb& a, const Aabb& b);
Aabb intersection(const Aabb& a, const Aabb& b);  // may be empty

// The smallest box containing m applied to every point of `box` (Arvo 1990),
// widened by a bound on float rounding so that it is conservative: every
// corner of `box`, transformed exactly, lies inside the result. An empty box
// stays empty.
Aabb transform(const Affine3& m, const Aabb& box);

}  // namespace sinew
