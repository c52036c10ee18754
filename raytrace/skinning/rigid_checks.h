// Escape checks that hold by construction, found once per character.
//
// A vertex whose only influence is bone b with weight exactly 1 moves
// rigidly with b: its skinned position is B_b p (the blend of one weight 1
// is B_b itself, bit for bit, on both skinning paths) and carried back
// into b's frame it is p again, up to the rounding the check's tolerance
// covers (frame_state.cpp, update_bone_frames). So its check against b,
// held to its own box (no cluster boxes: such a check has none, fuzzy_bake.cpp
// ranks only vertices another bone moves), passes whenever p lies in that
// box and the skinned position is finite. On fine meshes nearly half the
// checks are such, and as many blocks of eight vertices are nothing else;
// the escape check spends nothing on them but the finiteness test and the
// bone box (skinning.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/skinning/packed_influences.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::rt {

// The vertices of a block: the AVX2 skinning and check width.
inline constexpr std::size_t kRigidBlockVertices = 8;
inline constexpr std::uint16_t kNotRigid = kNoGroupBone;

// Per block of kRigidBlockVertices vertices (the last, partial block
// included): the bone all its checks are rigid in, when the block's group
// of `influences` (pack_influences(mesh)) is rigid on that bone
// (PackedInfluences::group_bone: one non-zero weight, exactly 1, a vertex)
// and each of its vertices has exactly one check, against that bone,
// ranked kSharedCheckBox when `check_rank` is given, its rest position
// inside the check's box; else kNotRigid. A partial block, a bone >=
// kNotRigid or arrays shorter than the mesh make kNotRigid.
std::vector<std::uint16_t> find_rigid_check_blocks(const SkinnedMesh& mesh, const PackedInfluences& influences,
                                                   std::span<const std::uint32_t> vertex_check_begin,
                                                   std::span<const VertexCheck> vertex_checks,
                                                   std::span<const std::uint32_t> check_rank);

}  // namespace sinew::rt
