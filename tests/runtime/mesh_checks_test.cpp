// check_skinned_mesh / check_triangle_mesh: every field a mesh path relies
// on is refused by name, with the origin's file and field prefix, and a
// well-formed mesh passes (the values are hand-checked).
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>

#include "runtime/mesh/mesh_checks.h"

namespace sinew {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Two triangles over four vertices, two joints, two materials.
SkinnedMesh quad() {
  SkinnedMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  m.normals.assign(4, Vec3(0, 0, 1));
  m.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)};
  m.joints.assign(4, {});
  m.weights.assign(4, {});
  for (std::size_t v = 0; v < 4; ++v) {
    m.joints[v][0] = static_cast<std::uint16_t>(v % 2);
    m.weights[v][0] = 1.0f;
  }
  m.triangles = {{0, 1, 2}, {2, 1, 3}};
  m.triangle_material = {0, 1};
  m.material_colors = {Vec3(0.5f), Vec3(0.25f)};
  return m;
}

constexpr std::size_t kJoints = 2;

TEST(MeshChecks, AWellFormedMeshPasses) {
  EXPECT_TRUE(check_skinned_mesh({}, quad(), kJoints).ok());
  SkinnedMesh bare = quad();
  bare.normals.clear();
  bare.uvs.clear();
  bare.triangle_material.clear();
  bare.material_colors.clear();
  EXPECT_TRUE(check_skinned_mesh({}, bare, kJoints).ok());
  // Material 0 without colours is the renderer's default colour.
  bare.triangle_material = {0, 0};
  EXPECT_TRUE(check_skinned_mesh({}, bare, kJoints).ok());
}

TEST(MeshChecks, EveryBrokenFieldIsNamedWithItsIndices) {
  struct Case {
    std::function<void(SkinnedMesh&)> damage;
    std::string field;
    std::string value;
  };
  const Case cases[] = {
      {[](SkinnedMesh& m) { m.positions[2].y = kNaN; }, "positions[2]", "0 nan 0"},
      {[](SkinnedMesh& m) { m.normals[3].z = kInf; }, "normals[3]", "0 0 inf"},
      {[](SkinnedMesh& m) { m.uvs[1].x = -kInf; }, "uvs[1]", "-inf 0"},
      {[](SkinnedMesh& m) { m.material_colors[1].x = kNaN; }, "material_colors[1]", "nan 0.25 0.25"},
      {[](SkinnedMesh& m) { m.joints[3][5] = 2; }, "joints[3][5]", "2"},
      {[](SkinnedMesh& m) { m.weights[1][7] = -0.25f; }, "weights[1][7]", "-0.25"},
      {[](SkinnedMesh& m) { m.weights[0][0] = kNaN; }, "weights[0][0]", "nan"},
      {[](SkinnedMesh& m) { m.triangles[1][2] = 4; }, "triangles[1][2]", "4"},
      {[](SkinnedMesh& m) { m.triangle_material[1] = 2; }, "triangle_material[1]", "2"},
      {[](SkinnedMesh& m) { m.triangle_material.pop_back(); }, "triangle_material", "1 entries"},
      {[](SkinnedMesh& m) { m.joints.pop_back(); }, "joints", "3 entries"},
      {[](SkinnedMesh& m) { m.weights.push_back({}); }, "weights", "5 entries"},
      {[](SkinnedMesh& m) { m.normals.pop_back(); }, "normals", "3 entries"},
      {[](SkinnedMesh& m) { m.uvs.pop_back(); }, "uvs", "3 entries"},
      {[](SkinnedMesh& m) { m.material_colors.clear(); }, "triangle_material[1]", "1"},
  };
  for (const Case& c : cases) {
    SkinnedMesh m = quad();
    c.damage(m);
    const Status s = check_skinned_mesh({"hero.pack", "MESH."}, m, kJoints);
    ASSERT_FALSE(s.ok()) << c.field;
    EXPECT_EQ(s.code(), ErrorCode::kInvalidData) << c.field;
    EXPECT_EQ(s.file(), "hero.pack") << c.field;
    EXPECT_EQ(s.field(), "MESH." + c.field) << s.message();
    EXPECT_EQ(s.value(), c.value) << s.message();
  }
}

TEST(MeshChecks, UnweightedSlotsStillNeedAJointInRange) {
  // SIMD skinning gathers every slot's matrix, weighted or not.
  SkinnedMesh m = quad();
  m.joints[0][7] = 9;
  m.weights[0][7] = 0.0f;
  const Status s = check_skinned_mesh({}, m, kJoints);
  EXPECT_EQ(s.field(), "joints[0][7]") << s.message();
  EXPECT_TRUE(check_skinned_mesh({}, m, 10).ok());
}

TEST(MeshChecks, TriangleMeshesWithoutSkinning) {
  const SkinnedMesh m = quad();
  EXPECT_TRUE(check_triangle_mesh({"static_meshes[0]", ""}, m.positions, m.triangles, {}, {}).ok());
  const std::array<std::uint32_t, 3> bad[] = {{0, 1, 2}, {0, 1, 7}};
  const Status s = check_triangle_mesh({"static_meshes[0]", ""}, m.positions, bad, {}, {});
  EXPECT_EQ(s.message(), "static_meshes[0]: triangles[1][2] = 7: not below the vertex count (4)");
  // No positions: any triangle is out of range; no triangles: nothing to check.
  EXPECT_FALSE(check_triangle_mesh({}, {}, m.triangles, {}, {}).ok());
  EXPECT_TRUE(check_triangle_mesh({}, {}, {}, {}, {}).ok());
}

}  // namespace
}  // namespace sinew
