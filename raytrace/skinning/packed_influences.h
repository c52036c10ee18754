// A mesh's skinning influences repacked for the per-frame skinning kernel.
//
// SkinnedMesh keeps kMaxInfluences (8) weights and joints per vertex, 48
// bytes, though most vertices use one or two. Skinning reads every byte
// every frame, so the influences are packed to what each vertex uses.
//
// Here the vertices go in groups of eight (the AVX2 kernel's lanes). Each
// vertex's non-zero weights move to its first slots, in their order; a
// group keeps only as many slots as its busiest vertex uses, each slot as
// eight weights and eight joints, lane after lane (a lane past its own
// count has weight 0 and joint 0). The kernel loads a slot's weights as one
// register instead of transposing eight vertices' rows. Cally at 855,552
// triangles averages 1.84 slots a group: 11 bytes a vertex instead of 48.
//
// Blending visits each vertex's non-zero weights in the order the mesh
// lists them, as before, so the skinned positions keep their bits.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/mesh/skinned_mesh.h"

namespace sinew::rt {

inline constexpr std::size_t kInfluenceGroupLanes = 8;
inline constexpr std::uint16_t kNoGroupBone = 0xFFFF;

struct PackedInfluences {
  std::size_t vertex_count = 0;
  // Per group + 1: the group's first slot; group g holds slots
  // [group_slot_begin[g], group_slot_begin[g + 1]).
  std::vector<std::uint32_t> group_slot_begin;
  // Per slot, kInfluenceGroupLanes entries: one per vertex of its group.
  std::vector<float> weights;
  std::vector<std::uint16_t> joints;
  // Per group: the bone, when each of its eight vertices has one non-zero
  // weight, exactly 1, on it (rigid vertices: the kernel broadcasts that
  // bone, and rigid_checks.h skips their escape checks); else kNoGroupBone.
  std::vector<std::uint16_t> group_bone;

  std::size_t group_count() const { return group_slot_begin.empty() ? 0 : group_slot_begin.size() - 1; }
};

// Packs the influences of the vertices that have positions, joints and
// weights (the shortest of the three arrays). A weight counts as used unless
// it compares equal to zero (NaN counts, as the kernels count it).
PackedInfluences pack_influences(const SkinnedMesh& mesh);

}  // namespace sinew::rt
