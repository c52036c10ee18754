#include "raytrace/skinning/packed_influences.h"

#include <algorithm>
#include <array>

namespace sinew::rt {

PackedInfluences pack_influences(const SkinnedMesh& mesh) {
  PackedInfluences packed;
  packed.vertex_count = std::min({mesh.positions.size(), mesh.joints.size(), mesh.weights.size()});
  const std::size_t groups = (packed.vertex_count + kInfluenceGroupLanes - 1) / kInfluenceGroupLanes;
  packed.group_slot_begin.reserve(groups + 1);
  packed.group_slot_begin.push_back(0);
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t first = g * kInfluenceGroupLanes;
    const std::size_t lanes = std::min(kInfluenceGroupLanes, packed.vertex_count - first);
    // Each lane's used influences, in the mesh's order.
    std::array<std::array<float, kMaxInfluences>, kInfluenceGroupLanes> weights{};
    std::array<std::array<std::uint16_t, kMaxInfluences>, kInfluenceGroupLanes> joints{};
    std::size_t slots = 0;
    bool one_bone = lanes == kInfluenceGroupLanes;
    for (std::size_t lane = 0; lane < lanes; ++lane) {
      std::size_t used = 0;
      for (std::size_t k = 0; k < kMaxInfluences; ++k) {
        const float w = mesh.weights[first + lane][k];
        if (w == 0.0f) continue;
        weights[lane][used] = w;
        joints[lane][used] = mesh.joints[first + lane][k];
        ++used;
      }
      slots = std::max(slots, used);
      one_bone = one_bone && used == 1 && weights[lane][0] == 1.0f && joints[lane][0] == joints[0][0] &&
                 joints[lane][0] != kNoGroupBone;
    }
    packed.group_bone.push_back(one_bone ? joints[0][0] : kNoGroupBone);
    for (std::size_t s = 0; s < slots; ++s) {
      for (std::size_t lane = 0; lane < kInfluenceGroupLanes; ++lane) {
        packed.weights.push_back(weights[lane][s]);
        packed.joints.push_back(joints[lane][s]);
      }
    }
    packed.group_slot_begin.push_back(static_cast<std::uint32_t>(packed.group_slot_begin.back() + slots));
  }
  return packed;
}

}  // namespace sinew::rt
