// Ray types. Directions are NOT required to be unit length: rays transformed
// into a bone's frame keep t meaning the same distance parameter in both
// frames (paper section 4; docs/DESIGN.md section 1).
#pragma once

#include <cstdint>
#include <limits>

#include "runtime/math/types.h"

namespace sinew {

struct Ray {
  Vec3 origin{0.0f};
  float t_min = 0.0f;
  Vec3 direction{0.0f, 0.0f, 1.0f};
  float t_max = std::numeric_limits<float>::infinity();

  Vec3 at(float t) const { return origin + t * direction; }
};

inline constexpr std::uint32_t kInvalidId = 0xFFFFFFFFu;

// The nearest hit of a ray: t along the ray, barycentrics (u, v) of the
// triangle's second and third vertex, and which triangle of which instance.
struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f;
  float v = 0.0f;
  std::uint32_t triangle_id = kInvalidId;
  std::uint32_t instance_id = kInvalidId;

  bool valid() const { return triangle_id != kInvalidId; }
};

}  // namespace sinew
