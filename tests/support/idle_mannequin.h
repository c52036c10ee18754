// The mannequin baked in memory over its idle clip's keys only: small and
// quick to bake, and posing it with another clip (a kick) leaves that pose
// space, so tests can reach the escape check and the fallback. Baked once
// per test binary.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "animation/pose_space.h"
#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "runtime/jobs/job_system.h"

namespace sinew::testing_support {

struct BakedModel {
  character::Model model;
  character::InMemoryBake bake;
};

// `model` (the mannequin, or one made from it) baked over its idle clip's keys.
inline BakedModel bake_over_idle(character::Model model, rt::BoneTreeKind trees = rt::BoneTreeKind::kKdTree) {
  BakedModel out;
  out.model = std::move(model);
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {"idle"};
  request.pose_space.samples = 0;
  request.pose_space.every_frame_30hz = false;
  request.fuzzy.bone_trees = trees;
  // Small leaves, so that the mannequin's BVHs have inner nodes to walk.
  request.fuzzy.bvh.max_leaf_items = 4;
  JobSystem jobs(2);
  out.bake = character::bake_in_memory(out.model, request, jobs).value();
  return out;
}

inline BakedModel bake_idle_mannequin(rt::BoneTreeKind trees) {
  return bake_over_idle(content::make_mannequin().value(), trees);
}

// With the default kd-trees, or with BVH bone trees.
inline const BakedModel& idle_mannequin(rt::BoneTreeKind trees = rt::BoneTreeKind::kKdTree) {
  if (trees == rt::BoneTreeKind::kBvh) {
    static const BakedModel bvh = bake_idle_mannequin(rt::BoneTreeKind::kBvh);
    return bvh;
  }
  static const BakedModel kd = bake_idle_mannequin(rt::BoneTreeKind::kKdTree);
  return kd;
}

// The model posed by one clip alone at playback time `t`, placed by `instance`.
inline std::vector<Affine3> clip_pose(const character::Model& model, const std::string& clip, double t,
                                      const Affine3& instance = Affine3::identity()) {
  return character::clip_skinning(model, *model.find_clip(clip), t, instance).value();
}

}  // namespace sinew::testing_support
