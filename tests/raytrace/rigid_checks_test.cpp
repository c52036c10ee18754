// Tests for find_rigid_check_blocks(): which blocks of eight vertices it
// calls rigid, checked block by block on a hand-built mesh where each block
// breaks one condition (skinning_test.cpp checks that the escape check
// answers for rigid blocks as their computed checks do).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "raytrace/skinning/rigid_checks.h"

namespace sinew::rt {
namespace {

// Vertices, their checks and ranks, built block by block.
struct Builder {
  SkinnedMesh mesh;
  std::vector<std::uint32_t> begin{0};
  std::vector<VertexCheck> checks;
  std::vector<std::uint32_t> rank;

  // A vertex at `p` with the given influences and one check per bone in
  // `check_bones`, each box a unit box around p (ranked `r`).
  void add(const Vec3& p, std::initializer_list<std::pair<std::uint16_t, float>> influences,
           std::initializer_list<std::uint32_t> check_bones, std::uint32_t r = kSharedCheckBox) {
    mesh.positions.push_back(p);
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    std::size_t k = 0;
    for (const auto& [joint, weight] : influences) {
      joints[k] = joint;
      weights[k] = weight;
      ++k;
    }
    mesh.joints.push_back(joints);
    mesh.weights.push_back(weights);
    for (const std::uint32_t bone : check_bones) {
      checks.push_back({bone, Aabb{p - 1.0f, p + 1.0f}});
      rank.push_back(r);
    }
    begin.push_back(static_cast<std::uint32_t>(checks.size()));
  }
  // Seven rigid vertices on `bone` (a block needs one more).
  void add_seven_rigid(std::uint16_t bone) {
    for (int i = 0; i < 7; ++i) add(Vec3(static_cast<float>(i)), {{bone, 1.0f}}, {bone});
  }
};

TEST(RigidChecks, EachConditionDecidesItsBlock) {
  Builder b;
  const Vec3 p(0.5f, -2.0f, 3.0f);
  // 0: eight rigid vertices on bone 3, weight 1 in a later slot.
  b.add_seven_rigid(3);
  b.mesh.joints.back() = {0, 0, 3, 0, 0, 0, 0, 0};
  b.mesh.weights.back() = {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  b.add(p, {{3, 1.0f}}, {3});
  // 1: one vertex moved by two bones.
  b.add_seven_rigid(3);
  b.add(p, {{3, 0.5f}, {4, 0.5f}}, {3});
  // 2: one vertex's weights split over two slots of the same bone.
  b.add_seven_rigid(3);
  b.add(p, {{3, 0.5f}, {3, 0.5f}}, {3});
  // 3: one vertex rigid on bone 4 but checked against bone 3.
  b.add_seven_rigid(3);
  b.add(p, {{4, 1.0f}}, {3});
  // 4: one vertex with a weight that is not exactly 1.
  b.add_seven_rigid(3);
  b.add(p, {{3, std::nextafter(1.0f, 0.0f)}}, {3});
  // 5: one vertex with a NaN weight.
  b.add_seven_rigid(3);
  b.add(p, {{3, std::numeric_limits<float>::quiet_NaN()}}, {3});
  // 6: one vertex with two checks (the block's checks are not one a vertex).
  b.add_seven_rigid(3);
  b.add(p, {{3, 1.0f}}, {3, 3});
  // 7: one vertex without a check.
  b.add_seven_rigid(3);
  b.add(p, {{3, 1.0f}}, {});
  // 8: one check held to cluster boxes (ranked).
  b.add_seven_rigid(3);
  b.add(p, {{3, 1.0f}}, {3}, 0);
  // 9: one rest position one float outside its box.
  b.add_seven_rigid(3);
  b.add(p, {{3, 1.0f}}, {3});
  b.checks.back().box.upper.y = std::nextafter(p.y, -1e9f);
  // 10: the rest position on the box's faces (inside).
  b.add_seven_rigid(3);
  b.add(p, {{3, 1.0f}}, {3});
  b.checks.back().box = Aabb{p, p};
  // 11: two bones, four rigid vertices each.
  for (int i = 0; i < 4; ++i) b.add(p, {{3, 1.0f}}, {3});
  for (int i = 0; i < 4; ++i) b.add(p, {{5, 1.0f}}, {5});
  // 12: rigid on bone kNotRigid itself (not representable).
  for (int i = 0; i < 8; ++i) b.add(p, {{kNotRigid, 1.0f}}, {kNotRigid});
  // 13: a partial block of five rigid vertices.
  for (int i = 0; i < 5; ++i) b.add(p, {{3, 1.0f}}, {3});

  const std::vector<std::uint16_t> expected{3,         kNotRigid, kNotRigid, kNotRigid, kNotRigid,
                                            kNotRigid, kNotRigid, kNotRigid, kNotRigid, kNotRigid,
                                            3,         kNotRigid, kNotRigid, kNotRigid};
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, b.checks, b.rank), expected);
  // Without ranks (no clusters) block 8 is rigid too.
  std::vector<std::uint16_t> unranked = expected;
  unranked[8] = 3;
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, b.checks, {}), unranked);
}

TEST(RigidChecks, ShortArraysMakeNoRigidBlock) {
  Builder b;
  b.add_seven_rigid(2);
  b.add(Vec3(1.0f), {{2, 1.0f}}, {2});
  ASSERT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, b.checks, {}), std::vector<std::uint16_t>{2});
  // Check begins for fewer vertices than the mesh has.
  const std::vector<std::uint32_t> short_begin(b.begin.begin(), b.begin.end() - 1);
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), short_begin, b.checks, {}), std::vector<std::uint16_t>{kNotRigid});
  // Fewer checks than the begins name.
  const std::vector<VertexCheck> short_checks(b.checks.begin(), b.checks.end() - 1);
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, short_checks, {}), std::vector<std::uint16_t>{kNotRigid});
  // Fewer ranks than checks.
  const std::vector<std::uint32_t> short_rank(b.checks.size() - 1, kSharedCheckBox);
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, b.checks, short_rank), std::vector<std::uint16_t>{kNotRigid});
  // Weights for fewer vertices than the mesh has.
  b.mesh.weights.pop_back();
  EXPECT_EQ(find_rigid_check_blocks(b.mesh, pack_influences(b.mesh), b.begin, b.checks, {}), std::vector<std::uint16_t>{kNotRigid});
  // No vertices.
  EXPECT_TRUE(find_rigid_check_blocks(SkinnedMesh{}, PackedInfluences{}, std::vector<std::uint32_t>{0}, {}, {}).empty());
}

}  // namespace
}  // namespace sinew::rt
