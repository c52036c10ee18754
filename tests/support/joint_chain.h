// The animation tests' skeletons: a chain of named joints, each the child of
// the one before, at identity rest transforms that a test then sets.
#pragma once

#include <initializer_list>

#include "animation/skeleton.h"

namespace sinew::testing_support {

inline anim::RawSkeleton joint_chain(std::initializer_list<const char*> names) {
  anim::RawSkeleton raw;
  for (const char* name : names) {
    anim::RawJoint joint;
    joint.name = name;
    joint.parent = raw.joints.empty() ? anim::kNoParent : static_cast<int>(raw.joints.size()) - 1;
    raw.joints.push_back(joint);
  }
  return raw;
}

}  // namespace sinew::testing_support
