// Clips: each glTF animation's translation, rotation and scale channels on
// joints become tracks of one anim::Clip, with the folds the skeleton plan
// chose applied to their keys. Separate because clips need the skeleton
// (plan, joints' order) but nothing of the meshes.
#pragma once

#include <vector>

#include "editor/import/gltf_skeleton.h"

namespace sinew::editor::gltf_detail {

Expected<std::vector<anim::Clip>> build_clips(const Ctx& c, const SkeletonPlan& plan,
                                              const anim::Skeleton& skeleton,
                                              const std::vector<int>& raw_to_sorted);

}  // namespace sinew::editor::gltf_detail
