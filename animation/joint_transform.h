// JointTransform: a joint's local transform as translation, rotation and
// scale (glTF's TRS, Cal3D's translation + rotation). Poses are arrays of
// these, one per joint, in the skeleton's joint order.
#pragma once

#include "runtime/math/affine.h"
#include "runtime/math/types.h"

namespace sinew::anim {

struct JointTransform {
  Vec3 translation{0.0f};
  Quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // glm order: w, x, y, z
  Vec3 scale{1.0f};

  Affine3 to_affine() const { return Affine3::from_trs(translation, rotation, scale); }
};

}  // namespace sinew::anim
