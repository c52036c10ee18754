#include <gtest/gtest.h>

#include "animation/pose.h"
#include "animation/reference_skinning.h"
#include "tests/support/joint_chain.h"

namespace sinew::anim {
namespace {

constexpr float kPi = 3.14159265358979f;

void expect_near(const Vec3& a, const Vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// A two-bone arm along +x: shoulder at the origin, elbow at x = 2.
Skeleton arm() {
  RawSkeleton raw = testing_support::joint_chain({"shoulder", "elbow"});
  raw.joints[1].rest.translation = Vec3(2, 0, 0);
  raw.joints[1].inverse_bind = Affine3::translation({-2, 0, 0});
  return *Skeleton::build(raw, "arm");
}

TEST(Pose, LocalToModelHandChecked) {
  const Skeleton s = arm();
  std::vector<JointTransform> local(2);
  ASSERT_TRUE(rest_pose(s, local).ok());
  // Rotate the shoulder 90 degrees about z: the elbow moves to (0, 2, 0).
  local[0].rotation = glm::angleAxis(kPi / 2, Vec3(0, 0, 1));
  std::vector<Affine3> model(2);
  ASSERT_TRUE(local_to_model(s, local, model).ok());
  expect_near(model[1].translation_part(), {0, 2, 0});
  expect_near(model[1].transform_point({1, 0, 0}), {0, 3, 0});
}

TEST(Pose, RestPoseSkinsToTheBindMesh) {
  const Skeleton s = arm();
  std::vector<JointTransform> local(2);
  ASSERT_TRUE(rest_pose(s, local).ok());
  std::vector<Affine3> model(2), skin(2);
  ASSERT_TRUE(local_to_model(s, local, model).ok());
  ASSERT_TRUE(skinning_matrices(s, model, Affine3::identity(), skin).ok());
  for (const Affine3& m : skin) expect_near(m.transform_point({1, 2, 3}), {1, 2, 3});
}

TEST(Pose, BlendedVertexHandChecked) {
  const Skeleton s = arm();
  SkinnedMesh mesh;
  mesh.positions = {{2, 0, 0}, {3, 0, 0}};
  mesh.normals = {{0, 1, 0}, {0, 1, 0}};
  mesh.joints = {{0, 1}, {1}};
  mesh.weights = {{0.5f, 0.5f}, {1.0f}};
  std::vector<JointTransform> local(2);
  ASSERT_TRUE(rest_pose(s, local).ok());
  local[1].rotation = glm::angleAxis(kPi / 2, Vec3(0, 0, 1));  // bend the elbow up
  std::vector<Affine3> model(2), skin(2);
  ASSERT_TRUE(local_to_model(s, local, model).ok());
  const Affine3 instance = Affine3::translation({10, 0, 0});
  ASSERT_TRUE(skinning_matrices(s, model, instance, skin).ok());
  std::vector<Vec3> pos(2), nrm(2);
  ASSERT_TRUE(skin_reference(mesh, skin, pos, nrm).ok());
  // Vertex 0 sits on the elbow: both bones map it to (2, 0, 0) (+ instance).
  expect_near(pos[0], {12, 0, 0});
  // Vertex 1 follows the elbow: one unit along the bent bone, (2, 1, 0).
  expect_near(pos[1], {12, 1, 0});
  expect_near(nrm[1], {-1, 0, 0});
  // Vertex 0's normal blends (0,1,0) and (-1,0,0) equally, renormalised.
  expect_near(nrm[0], glm::normalize(Vec3(-1, 1, 0)));
}

TEST(Pose, SizeMismatchesAreErrors) {
  const Skeleton s = arm();
  std::vector<JointTransform> local(3);
  std::vector<Affine3> model(2);
  EXPECT_EQ(local_to_model(s, local, model).code(), ErrorCode::kInvalidArgument);
  SkinnedMesh mesh;
  mesh.positions = {{0, 0, 0}};
  mesh.joints = {{5}};
  mesh.weights = {{1.0f}};
  std::vector<Affine3> skin(2);
  std::vector<Vec3> out(1);
  EXPECT_EQ(skin_reference(mesh, skin, out, {}).code(), ErrorCode::kOutOfBounds);
}

}  // namespace
}  // namespace sinew::anim
