// The bridge from an imported model to the ray tracer: pose-space samples as
// skinning matrices, a clip's pose at a time, and the in-memory bake
// (docs/DESIGN.md section 3, offline half, without the pack).
//
// raytrace/ never sees animation types: it gets spans of Affine3 skinning
// matrices, produced here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "animation/joint_limits.h"
#include "animation/pose_space.h"
#include "character/model.h"
#include "raytrace/bake/fuzzy_bake.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"

namespace sinew {
class JobSystem;
}

namespace sinew::character {

// The pose space `render` bakes by default: every clip of the model, at
// every key time and every 1/30 s.
anim::PoseSpaceDesc default_pose_space();

// Skinning matrices (bind pose -> model space) of every pose of the space,
// sample-major (poses x joints). A clip space over a model without clips
// gives the rest pose alone, so a static skinned model still bakes.
// `max_bytes` bounds the matrices produced: a space that would need more is
// refused (kLimitExceeded, field "pose_space") as soon as it passes the
// bound, so the refusal costs at most `max_bytes`.
Expected<std::vector<Affine3>> pose_space_skinning(const Model& model,
                                                   const anim::PoseSpaceDesc& space,
                                                   std::span<const anim::JointLimit> limits,
                                                   std::size_t max_bytes = SIZE_MAX);

// Skinning matrices of the model posed by one clip alone at weight 1 at
// playback time `seconds` (looping), placed in the world by `instance`.
Expected<std::vector<Affine3>> clip_skinning(const Model& model, const anim::Clip& clip,
                                             double seconds, const Affine3& instance = Affine3::identity());

// Skinning matrices of the model at its skeleton's rest pose, placed in the
// world by `placement`.
Expected<std::vector<Affine3>> rest_skinning(const Model& model, const Affine3& placement = Affine3::identity());

struct BakeRequest {
  anim::PoseSpaceDesc pose_space = default_pose_space();
  // When not empty: the pose samples themselves, skinning matrices
  // sample-major (a whole number of poses), baked instead of pose_space.
  // `render` bakes only the poses it draws this way.
  std::vector<Affine3> poses;
  std::vector<anim::JointLimit> limits;  // kLimits only
  rt::FuzzyBakeOptions fuzzy;
  // The bake's working set may not exceed this. The fuzzy boxes already fit
  // fuzzy.memory_budget_bytes (bones are processed in chunks); what is left
  // bounds the pose samples, which the bake holds twice (the matrices and
  // their inverses): samples x joints x 48 bytes x 2.
  std::size_t max_memory_bytes = std::size_t{8} << 30;
};

// What a bake holds at its peak, estimated from its large buffers (the
// same ledger the fuzzy bake keeps; allocator overhead and the kd builders'
// scratch are not counted).
struct BakeMemory {
  std::size_t pose_samples = 0;  // the samples' skinning matrices
  std::size_t fuzzy_peak = 0;    // the fuzzy bake's own peak (inverses, boxes, trees)
  std::size_t peak() const { return pose_samples + fuzzy_peak; }
};

struct InMemoryBake {
  rt::FuzzyCharacterData fuzzy;
  double pose_sampling_ms = 0.0;  // producing the samples' matrices (before the fuzzy bake)
  BakeMemory memory;
};

// Errors besides the fuzzy bake's: kInvalidArgument when max_memory_bytes
// leaves no room beside fuzzy.memory_budget_bytes, or `poses` is not a
// whole number of poses; kLimitExceeded when the pose space needs more than
// that room (refused while sampling, before the matrices outgrow the bound)
// or has a clip too long for it (naming the model's file).

Expected<InMemoryBake> bake_in_memory(const Model& model, const BakeRequest& request, JobSystem& jobs);

// How far poses lie outside a baked pose space: per pose, the share of the
// model's triangles that leave their fuzzy boxes (escape). Those render
// exactly, through a world-space tree built for them each frame: the
// fallback, whose cost grows with them.
struct OutsideShare {
  std::size_t poses = 0;
  double mean = 0.0;  // share of the triangles (0 to 1), averaged over the poses
  double max = 0.0;   // the largest share of one pose
};
// `poses`: skinning matrices sample-major, as pose_space_skinning gives
// them. Errors: kInvalidArgument when `poses` is not a whole number of
// poses; the scene's, for data that does not fit the mesh.
Expected<OutsideShare> triangles_outside(const Model& model, const rt::FuzzyCharacterView& fuzzy,
                                         std::span<const Affine3> poses, JobSystem& jobs);
// The poses of `clip` every 1/30 s over its length (its first key time, at
// least), at most `max_poses` of them evenly spread, as skinning matrices.
Expected<std::vector<Affine3>> clip_poses(const Model& model, const anim::Clip& clip, std::size_t max_poses);

}  // namespace sinew::character
