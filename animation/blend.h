// Blend-layer evaluation: the second half of Cal3D's mixer
// (CalMixer::updateSkeleton plus CalBone::blendState/lockState), kept apart
// from the scheduling in mixer.h so that the per-frame pose job takes spans
// in and out and the Mixer itself never touches clip data (STYLE.md item 4).
//
// Ownership: nothing here owns clips, caches or poses; callers pass spans.
// Units: layer times are seconds on the clip's own timeline (already wrapped
// for cycles), weights are Cal3D's relative weights (any value >= 0).
//
// Cal3D's accumulation, reproduced exactly (0.11.0 bone.cpp):
//   blendState(w, T, R): the first state of a group is copied with
//     weight_abs = w; later ones blend in by factor w / (weight_abs + w)
//     (translation lerp, CalQuaternion::blend for rotation), weight_abs += w.
//     So within a group the result is the normalised weighted blend.
//   lockState(): clamp weight_abs to 1 - weight; if weight_abs > 0 the group
//     result is copied (first group) or blended in by
//     weight_abs / (weight + weight_abs), weight += weight_abs.
//     So the first group (actions) takes min(sum, 1) of the pose and later
//     groups (cycles) only the weight that is left.
//   Joints no layer touched (accumulated weight 0) take the rest pose; a
//   joint touched with a weight below 1 is fully driven by its layers (Cal3D
//   never blends towards the rest pose).
// Scale, which Cal3D lacks, blends linearly exactly like translation.
#pragma once

#include <span>
#include <vector>

#include "animation/clip.h"
#include "animation/joint_transform.h"
#include "animation/skeleton.h"
#include "runtime/core/status.h"

namespace sinew::anim {

// One sampled clip in a blend, as emitted by Mixer::layers().
struct BlendLayer {
  int clip = 0;         // index into the clip span
  float time = 0.0f;    // clip-local seconds to sample at
  float weight = 0.0f;  // Cal3D relative weight, >= 0
  bool action = false;  // actions accumulate first and override cycles
};

// Reusable working memory so that steady-state evaluation allocates nothing.
// Sized on first use; holds no state between calls.
struct BlendScratch {
  std::vector<JointTransform> sampled;  // one clip's sample
  std::vector<JointTransform> group;    // Cal3D's "absolute" (unlocked) state
  std::vector<float> group_weight;      // Cal3D's m_accumulatedWeightAbsolute
  std::vector<float> weight;            // Cal3D's m_accumulatedWeight
};

// Samples every layer and accumulates them in order with Cal3D's rules.
// A group is a run of consecutive layers with the same `action` flag; each
// group ends with a lock (Mixer::layers() emits all actions, then all cycles,
// which is exactly Cal3D's two locks). `caches` has one entry per clip;
// `out_local` has joint_count() entries and is fully overwritten.
// `scratch` may be null, in which case a temporary is allocated.
// Errors (kInvalidArgument, nothing written): span sizes, clip indices out
// of range, negative or non-finite layer weights or times.
Status evaluate_layers(const Skeleton& skeleton, std::span<const Clip> clips,
                       std::span<const BlendLayer> layers, std::span<SamplingCache> caches,
                       std::span<JointTransform> out_local, BlendScratch* scratch = nullptr);

// CalQuaternion::blend(d, q) on glm quaternions: slerp along the shorter arc
// with no renormalisation, falling back to a plain lerp when the two are
// within 1e-6 of parallel. Not slerp_shortest: the oracle comparison against
// Cal3D needs its exact arithmetic.
Quat cal3d_quat_blend(const Quat& a, const Quat& b, float d);

}  // namespace sinew::anim
