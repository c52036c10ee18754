// Reference linear blend skinning: p' = sum_i w_i * skin[j_i] * p, in double
// precision, one vertex at a time. It is the oracle for the ray tracer's
// SIMD skinning and the editor's pose sampling, so it favours obviousness
// over speed. Normals use the same blended matrix and are renormalised
// (exact for rigid and uniformly scaled bones).
#pragma once

#include <span>

#include "runtime/core/status.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::anim {

// `skin` holds one matrix per joint; `positions` (and `normals`, when not
// empty) receive vertex_count() entries. Errors: kInvalidArgument for a span
// of the wrong size, kOutOfBounds for a joint index past skin.size().
Status skin_reference(const SkinnedMesh& mesh, std::span<const Affine3> skin,
                      std::span<Vec3> positions, std::span<Vec3> normals);

}  // namespace sinew::anim
