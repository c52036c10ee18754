// Skeleton: immutable joint hierarchy shared by every instance of a
// character (Cal3D's CalCoreSkeleton, ozz's Skeleton).
//
// Joints are stored in topological order: a joint's parent always has a
// smaller index, so local-to-model is one forward pass. Importers describe
// joints in any order as a RawSkeleton; Skeleton::build sorts them and
// reports the permutation so vertex joint indices can be remapped.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animation/joint_transform.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"

namespace sinew::anim {

inline constexpr int kNoParent = -1;
// Far beyond any character (Cally has 37 joints, Paladin 58); keeps a
// corrupt file from making us allocate per-joint state by the million.
inline constexpr std::size_t kMaxJoints = 4096;

struct RawJoint {
  std::string name;
  int parent = kNoParent;       // index into RawSkeleton::joints, or kNoParent
  JointTransform rest;          // bind pose, relative to the parent
  Affine3 inverse_bind;         // model space -> joint space at bind time
};

struct RawSkeleton {
  std::vector<RawJoint> joints;
};

class Skeleton {
 public:
  Skeleton() = default;

  // Validates and sorts `raw`. `source` names the file for messages.
  // Errors: kLimitExceeded (too many joints), kOutOfBounds (parent index),
  // kInvalidData (cycle, non-finite or zero-length rotation, non-finite
  // matrices), kDuplicate (two joints with one non-empty name).
  // `raw_to_sorted`, when given, receives for each raw joint its new index.
  static Expected<Skeleton> build(const RawSkeleton& raw, std::string_view source,
                                  std::vector<int>* raw_to_sorted = nullptr);

  std::size_t joint_count() const { return parents_.size(); }
  std::span<const int> parents() const { return parents_; }
  std::span<const JointTransform> rest_pose() const { return rest_; }
  std::span<const Affine3> inverse_bind() const { return inverse_bind_; }
  std::span<const std::string> names() const { return names_; }

  std::optional<int> find(std::string_view name) const;

 private:
  std::vector<int> parents_;
  std::vector<JointTransform> rest_;
  std::vector<Affine3> inverse_bind_;
  std::vector<std::string> names_;
};

}  // namespace sinew::anim
