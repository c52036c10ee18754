#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "runtime/math/aabb.h"

namespace sinew {
namespace {

TEST(Aabb, EmptyIsIdentityForUnion) {
  Aabb e = Aabb::empty();
  EXPECT_TRUE(e.is_empty());
  EXPECT_EQ(e.surface_area(), 0.0f);
  Aabb b{{0, 1, 2}, {3, 4, 5}};
  Aabb m = merge(e, b);
  EXPECT_EQ(m.lower, b.lower);
  EXPECT_EQ(m.upper, b.upper);
}

TEST(Aabb, SurfaceAreaHandChecked) {
  EXPECT_FLOAT_EQ((Aabb{{0, 0, 0}, {1, 2, 3}}).surface_area(), 2.0f * (2 + 6 + 3));
  EXPECT_FLOAT_EQ((Aabb{{-1, -1, -1}, {1, 1, 1}}).surface_area(), 24.0f);
  // A flat box (a triangle in the xy plane) has area 2*w*h and is not empty.
  Aabb flat{{0, 0, 5}, {2, 3, 5}};
  EXPECT_FALSE(flat.is_empty());
  EXPECT_FLOAT_EQ(flat.surface_area(), 12.0f);
  // A single point: zero area, not empty.
  EXPECT_EQ(Aabb::from_point({1, 2, 3}).surface_area(), 0.0f);
}

TEST(Aabb, ExtendContainsAndIntersection) {
  Aabb b;
  b.extend(Vec3(1, 2, 3));
  b.extend(Vec3(-1, 5, 0));
  EXPECT_EQ(b.lower, Vec3(-1, 2, 0));
  EXPECT_EQ(b.upper, Vec3(1, 5, 3));
  EXPECT_TRUE(b.contains(Vec3(0, 3, 1)));
  EXPECT_FALSE(b.contains(Vec3(0, 6, 1)));
  EXPECT_TRUE(b.contains(Aabb::empty()));
  Aabb c{{0, 0, 0}, {10, 3, 1}};
  Aabb i = intersection(b, c);
  EXPECT_EQ(i.lower, Vec3(0, 2, 0));
  EXPECT_EQ(i.upper, Vec3(1, 3, 1));
  EXPECT_TRUE(intersection(Aabb{{0, 0, 0}, {1, 1, 1}}, Aabb{{2, 2, 2}, {3, 3, 3}}).is_empty());
}

TEST(Aabb, TransformOfEmptyStaysEmpty) {
  EXPECT_TRUE(transform(Affine3::translation({1, 2, 3}), Aabb::empty()).is_empty());
}

TEST(Aabb, TransformByRotationHandChecked) {
  // 90 degrees about z: x -> y, y -> -x.
  Affine3 m;
  m.rows[0] = Vec4(0, -1, 0, 10);
  m.rows[1] = Vec4(1, 0, 0, 0);
  m.rows[2] = Vec4(0, 0, 1, 0);
  Aabb r = transform(m, Aabb{{0, 0, 0}, {1, 2, 3}});
  EXPECT_NEAR(r.lower.x, 8.0f, 1e-5f);
  EXPECT_NEAR(r.upper.x, 10.0f, 1e-5f);
  EXPECT_NEAR(r.lower.y, 0.0f, 1e-5f);
  EXPECT_NEAR(r.upper.y, 1.0f, 1e-5f);
  EXPECT_NEAR(r.upper.z, 3.0f, 1e-5f);
}

// Conservativeness on random affines: all eight corners, transformed in
// double precision (the exact reference), lie inside the float result.
TEST(Aabb, TransformIsConservativeOnRandomAffines) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-6, 6);
  int checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const float scale = std::ldexp(1.0f, exponent(rng) * 2);     // 1e-4 .. 4e3
    const float offset = std::ldexp(1.0f, exponent(rng) * 3);    // far from the origin too
    Affine3 m;
    for (auto& row : m.rows) row = Vec4(unit(rng) * scale, unit(rng) * scale, unit(rng) * scale,
                                        unit(rng) * offset);
    Vec3 a(unit(rng), unit(rng), unit(rng));
    Vec3 b(unit(rng), unit(rng), unit(rng));
    a *= offset;
    b *= offset;
    Aabb box = Aabb::from_corners(a, b);
    Aabb r = transform(m, box);
    for (int corner = 0; corner < 8; ++corner) {
      const double p[3] = {(corner & 1) ? box.upper.x : box.lower.x,
                           (corner & 2) ? box.upper.y : box.lower.y,
                           (corner & 4) ? box.upper.z : box.lower.z};
      for (int i = 0; i < 3; ++i) {
        const Vec4& row = m.rows[static_cast<std::size_t>(i)];
        const double q = double(row.x) * p[0] + double(row.y) * p[1] + double(row.z) * p[2] +
                         double(row.w);
        ASSERT_LE(double(r.lower[i]), q) << "trial " << trial << " axis " << i;
        ASSERT_GE(double(r.upper[i]), q) << "trial " << trial << " axis " << i;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 20000 * 8 * 3);
}

// The result is also tight: for a pure rotation about an axis it does not
// exceed the exact bound by more than float noise.
TEST(Aabb, TransformIsTight) {
  const Affine3 m = Affine3::from_trs({1, 2, 3}, glm::angleAxis(0.7f, glm::normalize(Vec3(1, 2, 3))),
                                      Vec3(2.0f));
  Aabb box{{-1, -2, -3}, {4, 5, 6}};
  Aabb r = transform(m, box);
  Aabb exact;
  for (int corner = 0; corner < 8; ++corner) {
    exact.extend(m.transform_point({(corner & 1) ? box.upper.x : box.lower.x,
                                    (corner & 2) ? box.upper.y : box.lower.y,
                                    (corner & 4) ? box.upper.z : box.lower.z}));
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.lower[i], exact.lower[i], 1e-4f);
    EXPECT_NEAR(r.upper[i], exact.upper[i], 1e-4f);
  }
}

}  // namespace
}  // namespace sinew
