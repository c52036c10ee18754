#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/math/affine.h"

namespace sinew {
namespace {

void expect_near(const Vec3& a, const Vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(Affine3, MatchesGlmMat4) {
  const Mat4 m = glm::scale(glm::rotate(glm::translate(Mat4(1.0f), Vec3(1, -2, 3)), 0.4f,
                                        Vec3(0, 1, 0)),
                            Vec3(2, 3, 4));
  const Affine3 a = Affine3::from_mat4(m);
  const Vec3 p(0.5f, -1.5f, 2.0f);
  const Vec4 ref = m * Vec4(p, 1.0f);
  expect_near(a.transform_point(p), Vec3(ref), 1e-5f);
  const Vec4 refv = m * Vec4(p, 0.0f);
  expect_near(a.transform_vector(p), Vec3(refv), 1e-5f);
  EXPECT_EQ(a.to_mat4(), m);
}

TEST(Affine3, FromTrsMatchesGlmComposition) {
  const Quat r = glm::angleAxis(1.1f, glm::normalize(Vec3(1, 1, 0)));
  const Affine3 a = Affine3::from_trs({4, 5, 6}, r, {1, 2, 3});
  const Mat4 ref = glm::translate(Mat4(1.0f), Vec3(4, 5, 6)) * glm::mat4_cast(r) *
                   glm::scale(Mat4(1.0f), Vec3(1, 2, 3));
  const Affine3 b = Affine3::from_mat4(ref);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(a(i, j), b(i, j), 1e-6f);
  EXPECT_NEAR(a.determinant(), 6.0f, 1e-5f);
}

TEST(Affine3, CompositionAppliesRightFirst) {
  const Affine3 t = Affine3::translation({1, 0, 0});
  const Affine3 s = Affine3::from_trs({0, 0, 0}, Quat(1, 0, 0, 0), {2, 2, 2});
  expect_near((t * s).transform_point({1, 1, 1}), {3, 2, 2}, 0);
  expect_near((s * t).transform_point({1, 1, 1}), {4, 2, 2}, 0);
}

TEST(Affine3, InverseOnRandomTransforms) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_real_distribution<float> s(0.1f, 10.0f);
  for (int i = 0; i < 1000; ++i) {
    const Quat r = glm::normalize(Quat(u(rng), u(rng), u(rng), u(rng)));
    const Affine3 m = Affine3::from_trs({u(rng) * 100, u(rng) * 100, u(rng) * 100}, r,
                                        {s(rng), s(rng), s(rng)});
    const Affine3 id = inverse(m) * m;
    const Vec3 p(u(rng), u(rng), u(rng));
    expect_near(id.transform_point(p), p, 2e-3f);
  }
}

TEST(Affine3, ZeroScaleInverseIsReportedNotFinite) {
  const Affine3 m = Affine3::from_trs({1, 2, 3}, Quat(1, 0, 0, 0), {0, 1, 1});
  EXPECT_TRUE(is_finite(m));
  EXPECT_FALSE(is_finite(inverse(m)));
}

}  // namespace
}  // namespace sinew
