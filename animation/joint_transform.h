// JointTransform: a joint's local transform as translation, rotation and
// scale (glTF's TRS, Cal3D's translation + rotation). Poses are arrays of
// these, one per joint, in the skeleton's joint order.
#pragma once

#include <cmath>
#include <limits>

#include "runtime/math/affine.h"
#include "runtime/math/types.h"

namespace sinew::anim {

// `q` at unit length, scaled in double (the squares of finite float
// components neither overflow nor underflow there). A q already unit within
// rounding is returned as it is: normalising stored, normalised rotations
// (a content pack's rest pose and keys) again keeps their bits, where
// glm::normalize may move the last one. q must not be zero.
inline Quat unit_rotation(const Quat& q) {
  const double x = static_cast<double>(q.x), y = static_cast<double>(q.y), z = static_cast<double>(q.z),
               w = static_cast<double>(q.w);
  const double len = std::sqrt(x * x + y * y + z * z + w * w);
  constexpr double kUnitTolerance = 4.0 * static_cast<double>(std::numeric_limits<float>::epsilon());
  if (std::fabs(len - 1.0) <= kUnitTolerance) return q;
  return Quat(static_cast<float>(w / len), static_cast<float>(x / len), static_cast<float>(y / len),
              static_cast<float>(z / len));
}

struct JointTransform {
  Vec3 translation{0.0f};
  Quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // glm order: w, x, y, z
  Vec3 scale{1.0f};

  Affine3 to_affine() const { return Affine3::from_trs(translation, rotation, scale); }
};

}  // namespace sinew::anim
