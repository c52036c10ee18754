#include "runtime/math/aabb.h"

#include <cmath>
#include <limits>

namespace sinew {

float Aabb::surface_area() const {
  if (is_empty()) return 0.0f;
  const Vec3 e = extent();
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

Aabb merge(const Aabb& a, const Aabb& b) {
  Aabb out = a;
  out.extend(b);
  return out;
}

Aabb intersection(const Aabb& a, const Aabb& b) {
  return {glm::max(a.lower, b.lower), glm::min(a.upper, b.upper)};
}

Aabb transform(const Affine3& m, const Aabb& box) {
  if (box.is_empty()) return box;
  // Per output axis, each input axis contributes its smaller and larger
  // product independently (Arvo). `magnitude` sums the absolute values of
  // every rounded term so the float error of the sum can be bounded.
  constexpr float kEps = std::numeric_limits<float>::epsilon() * 0.5f;  // unit roundoff
  // Products, three additions, the magnitude estimate and the final
  // widening each round once; 8u bounds their combined relative error
  // against `magnitude` with margin (pbrt's gamma(n) argument). The absolute
  // term covers products that underflowed to zero.
  constexpr float kGamma = 8.0f * kEps;
  constexpr float kTiny = std::numeric_limits<float>::min();
  Aabb out;
  for (int i = 0; i < 3; ++i) {
    const Vec4& row = m.rows[static_cast<std::size_t>(i)];
    float lo = row.w;
    float hi = row.w;
    float magnitude = std::fabs(row.w);
    for (int j = 0; j < 3; ++j) {
      const float a = row[j] * box.lower[j];
      const float b = row[j] * box.upper[j];
      lo += std::fmin(a, b);
      hi += std::fmax(a, b);
      magnitude += std::fmax(std::fabs(a), std::fabs(b));
    }
    const float slack = kGamma * magnitude + kTiny;
    out.lower[i] = lo - slack;
    out.upper[i] = hi + slack;
  }
  return out;
}

}  // namespace sinew
