#include "raytrace/skinning/rigid_checks.h"

#include <algorithm>

namespace sinew::rt {

namespace {

bool holds(const Aabb& box, const Vec3& p) {
  return p.x >= box.lower.x && p.y >= box.lower.y && p.z >= box.lower.z && p.x <= box.upper.x &&
         p.y <= box.upper.y && p.z <= box.upper.z;
}

// Whether vertex v's check c, against the bone its block is rigid on, holds
// by construction: no cluster boxes, the rest position inside its box.
bool rigid_check(const SkinnedMesh& mesh, std::size_t v, std::span<const VertexCheck> checks,
                 std::span<const std::uint32_t> check_rank, std::size_t c) {
  if (!check_rank.empty() && (c >= check_rank.size() || check_rank[c] != kSharedCheckBox)) return false;
  return holds(checks[c].box, mesh.positions[v]);
}

}  // namespace

std::vector<std::uint16_t> find_rigid_check_blocks(const SkinnedMesh& mesh, const PackedInfluences& influences,
                                                   std::span<const std::uint32_t> vertex_check_begin,
                                                   std::span<const VertexCheck> vertex_checks,
                                                   std::span<const std::uint32_t> check_rank) {
  const std::size_t vertices = mesh.vertex_count();
  const std::size_t blocks = (vertices + kRigidBlockVertices - 1) / kRigidBlockVertices;
  std::vector<std::uint16_t> bone(blocks, kNotRigid);
  static_assert(kRigidBlockVertices == kInfluenceGroupLanes, "a block is a group of the packed influences");
  if (influences.vertex_count < vertices || influences.group_bone.size() < blocks ||
      vertex_check_begin.size() < vertices + 1) {
    return bone;
  }
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t first = b * kRigidBlockVertices;
    if (first + kRigidBlockVertices > vertices) break;
    const std::uint32_t c0 = vertex_check_begin[first];
    if (c0 + kRigidBlockVertices > vertex_checks.size()) continue;
    const std::uint32_t block_bone = influences.group_bone[b];
    if (block_bone == kNoGroupBone) continue;
    bool rigid = true;
    for (std::size_t i = 0; i < kRigidBlockVertices && rigid; ++i) {
      const std::size_t c = c0 + i;
      rigid = vertex_check_begin[first + i + 1] == c + 1 && vertex_checks[c].bone == block_bone &&
              rigid_check(mesh, first + i, vertex_checks, check_rank, c);
    }
    if (rigid) bone[b] = static_cast<std::uint16_t>(block_bone);
  }
  return bone;
}

}  // namespace sinew::rt
