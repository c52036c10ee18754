// Pose -> matrices: the last step of animation and the whole interface to
// raytrace/ (docs/DESIGN.md section 3). Jobs take spans in and out, allocate
// nothing and never own their buffers.
#pragma once

#include <span>

#include "animation/joint_transform.h"
#include "animation/skeleton.h"
#include "runtime/core/status.h"
#include "runtime/math/affine.h"

namespace sinew::anim {

// Fills `local` with the skeleton's rest pose (the starting point of a
// sampled or blended pose: joints no clip animates keep it).
Status rest_pose(const Skeleton& skeleton, std::span<JointTransform> local);

// model[j] = model[parent(j)] * local[j], one pass in topological order.
// All spans have joint_count() entries.
Status local_to_model(const Skeleton& skeleton, std::span<const JointTransform> local,
                      std::span<Affine3> model);

// skin[j] = instance * model[j] * inverse_bind[j]: maps a bind-pose vertex
// to world space. This span is what the ray tracer consumes per frame.
Status skinning_matrices(const Skeleton& skeleton, std::span<const Affine3> model,
                         const Affine3& instance, std::span<Affine3> skin);

}  // namespace sinew::anim
