// Tests for pack_influences(): the layout the skinning kernels read, checked
// slot by slot against hand-built meshes (skinning_test.cpp checks what the
// kernels make of it against a double-precision reference).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "raytrace/skinning/packed_influences.h"

namespace sinew::rt {
namespace {

struct Influence {
  std::size_t slot;
  std::uint16_t joint;
  float weight;
};

void add_vertex(SkinnedMesh& mesh, std::initializer_list<Influence> influences) {
  mesh.positions.push_back(Vec3(static_cast<float>(mesh.positions.size())));
  std::array<std::uint16_t, kMaxInfluences> joints{};
  std::array<float, kMaxInfluences> weights{};
  for (const Influence& i : influences) {
    joints[i.slot] = i.joint;
    weights[i.slot] = i.weight;
  }
  mesh.joints.push_back(joints);
  mesh.weights.push_back(weights);
}

// Slot row `slot` (counted over all groups), lane `lane`.
float weight_at(const PackedInfluences& p, std::size_t slot, std::size_t lane) {
  return p.weights[slot * kInfluenceGroupLanes + lane];
}
std::uint16_t joint_at(const PackedInfluences& p, std::size_t slot, std::size_t lane) {
  return p.joints[slot * kInfluenceGroupLanes + lane];
}

TEST(PackedInfluences, UsedWeightsMoveToTheFirstSlotsInTheirOrderAndGroupsKeepTheirBusiestVertexsSlots) {
  SkinnedMesh mesh;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  add_vertex(mesh, {{0, 4, 1.0f}});                                     // lane 0: one influence
  add_vertex(mesh, {{2, 7, 0.25f}, {5, 9, 0.75f}});                     // lane 1: slots 2 and 5
  add_vertex(mesh, {{0, 1, 0.1f}, {1, 2, 0.2f}, {3, 3, 0.3f}, {6, 5, 0.2f}, {7, 6, 0.2f}});  // five
  add_vertex(mesh, {{6, 3, nan}});                                      // NaN counts as used
  add_vertex(mesh, {{0, 8, -0.0f}, {1, 2, 1.0f}});                      // -0 compares equal to 0
  for (int i = 0; i < 3; ++i) add_vertex(mesh, {{4, 11, 1.0f}});       // lanes 5-7
  add_vertex(mesh, {{1, 12, 0.5f}, {3, 13, 0.5f}});                     // second group, lane 0
  add_vertex(mesh, {{7, 14, 1.0f}});                                    // lane 1
  add_vertex(mesh, {{0, 15, 0.5f}, {2, 16, 0.5f}});                     // lane 2; lanes 3-7 absent

  const PackedInfluences p = pack_influences(mesh);
  EXPECT_EQ(p.vertex_count, 11u);
  ASSERT_EQ(p.group_count(), 2u);
  EXPECT_EQ(p.group_slot_begin, (std::vector<std::uint32_t>{0, 5, 7}));
  ASSERT_EQ(p.weights.size(), 7 * kInfluenceGroupLanes);
  ASSERT_EQ(p.joints.size(), 7 * kInfluenceGroupLanes);

  // Group 0, five slots (lane 2's count).
  EXPECT_EQ(weight_at(p, 0, 0), 1.0f);
  EXPECT_EQ(joint_at(p, 0, 0), 4);
  for (std::size_t s = 1; s < 5; ++s) {
    EXPECT_EQ(weight_at(p, s, 0), 0.0f) << s;
    EXPECT_EQ(joint_at(p, s, 0), 0) << s;
  }
  EXPECT_EQ(weight_at(p, 0, 1), 0.25f);
  EXPECT_EQ(joint_at(p, 0, 1), 7);
  EXPECT_EQ(weight_at(p, 1, 1), 0.75f);
  EXPECT_EQ(joint_at(p, 1, 1), 9);
  EXPECT_EQ(weight_at(p, 2, 1), 0.0f);
  const std::uint16_t lane2_joints[] = {1, 2, 3, 5, 6};
  const float lane2_weights[] = {0.1f, 0.2f, 0.3f, 0.2f, 0.2f};
  for (std::size_t s = 0; s < 5; ++s) {
    EXPECT_EQ(joint_at(p, s, 2), lane2_joints[s]) << s;
    EXPECT_EQ(weight_at(p, s, 2), lane2_weights[s]) << s;
  }
  EXPECT_TRUE(std::isnan(weight_at(p, 0, 3)));
  EXPECT_EQ(joint_at(p, 0, 3), 3);
  EXPECT_EQ(weight_at(p, 0, 4), 1.0f);
  EXPECT_EQ(joint_at(p, 0, 4), 2);
  EXPECT_EQ(weight_at(p, 1, 4), 0.0f);
  for (std::size_t lane = 5; lane < 8; ++lane) {
    EXPECT_EQ(weight_at(p, 0, lane), 1.0f);
    EXPECT_EQ(joint_at(p, 0, lane), 11);
  }

  // Group 1, two slots; the lanes past the mesh's end weigh nothing.
  EXPECT_EQ(weight_at(p, 5, 0), 0.5f);
  EXPECT_EQ(joint_at(p, 5, 0), 12);
  EXPECT_EQ(weight_at(p, 6, 0), 0.5f);
  EXPECT_EQ(joint_at(p, 6, 0), 13);
  EXPECT_EQ(weight_at(p, 5, 1), 1.0f);
  EXPECT_EQ(joint_at(p, 5, 1), 14);
  EXPECT_EQ(weight_at(p, 6, 1), 0.0f);
  EXPECT_EQ(joint_at(p, 5, 2), 15);
  EXPECT_EQ(joint_at(p, 6, 2), 16);
  for (std::size_t lane = 3; lane < 8; ++lane) {
    for (std::size_t s = 5; s < 7; ++s) {
      EXPECT_EQ(weight_at(p, s, lane), 0.0f);
      EXPECT_EQ(joint_at(p, s, lane), 0);
    }
  }
}

TEST(PackedInfluences, CoversOnlyVerticesWithPositionsJointsAndWeights) {
  SkinnedMesh mesh;
  for (int v = 0; v < 10; ++v) add_vertex(mesh, {{0, 1, 1.0f}});
  mesh.joints.resize(9);
  const PackedInfluences p = pack_influences(mesh);
  EXPECT_EQ(p.vertex_count, 9u);
  EXPECT_EQ(p.group_slot_begin, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(weight_at(p, 1, 0), 1.0f);
  EXPECT_EQ(weight_at(p, 1, 1), 0.0f);  // vertex 9 has no joints: left out

  EXPECT_EQ(pack_influences(SkinnedMesh{}).group_count(), 0u);
  EXPECT_EQ(pack_influences(SkinnedMesh{}).group_slot_begin, (std::vector<std::uint32_t>{0}));
}

TEST(PackedInfluences, AGroupOfUnweightedVerticesHasNoSlots) {
  SkinnedMesh mesh;
  for (int v = 0; v < 8; ++v) add_vertex(mesh, {});
  add_vertex(mesh, {{3, 2, 1.0f}});
  const PackedInfluences p = pack_influences(mesh);
  EXPECT_EQ(p.group_slot_begin, (std::vector<std::uint32_t>{0, 0, 1}));
  EXPECT_EQ(joint_at(p, 0, 0), 2);
}

// A group is rigid on a bone only when all eight vertices have one
// non-zero weight, exactly 1, on that bone (in any slot).
TEST(PackedInfluences, GroupBoneNamesGroupsRigidOnOneBone) {
  SkinnedMesh mesh;
  const auto seven = [&](std::uint16_t bone) {
    for (int i = 0; i < 7; ++i) add_vertex(mesh, {{0, bone, 1.0f}});
  };
  seven(4);
  add_vertex(mesh, {{3, 4, 1.0f}});  // 0: rigid on 4, the weight in slot 3
  seven(4);
  add_vertex(mesh, {{0, 5, 1.0f}});  // 1: another bone
  seven(4);
  add_vertex(mesh, {{0, 4, 0.5f}, {1, 4, 0.5f}});  // 2: two weights on the same bone
  seven(4);
  add_vertex(mesh, {{0, 4, std::nextafter(1.0f, 0.0f)}});  // 3: not exactly 1
  seven(4);
  add_vertex(mesh, {{0, 4, std::numeric_limits<float>::quiet_NaN()}});  // 4: NaN
  seven(2);
  add_vertex(mesh, {{0, 2, 1.0f}});  // 5: rigid on 2
  for (int i = 0; i < 8; ++i) add_vertex(mesh, {{0, kNoGroupBone, 1.0f}});  // 6: the sentinel's bone
  for (int i = 0; i < 5; ++i) add_vertex(mesh, {{0, 4, 1.0f}});             // 7: partial
  const PackedInfluences packed = pack_influences(mesh);
  EXPECT_EQ(packed.group_bone, (std::vector<std::uint16_t>{4, kNoGroupBone, kNoGroupBone, kNoGroupBone, kNoGroupBone,
                                                           2, kNoGroupBone, kNoGroupBone}));
}

}  // namespace
}  // namespace sinew::rt
