#include "raytrace/camera/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace sinew::rt {
namespace {

constexpr float kTol = 1e-6f;

PinholeCamera make_camera(const CameraDesc& desc, int width, int height) {
  Expected<PinholeCamera> camera = PinholeCamera::create(desc, width, height);
  EXPECT_TRUE(camera.ok()) << camera.status().message();
  return *camera;
}

void expect_vec_near(const Vec3& actual, const Vec3& expected, float tol) {
  EXPECT_NEAR(actual.x, expected.x, tol);
  EXPECT_NEAR(actual.y, expected.y, tol);
  EXPECT_NEAR(actual.z, expected.z, tol);
}

TEST(CameraConvention, BasisHandChecked) {
  // forward = (0,0,-1); right = forward x up = (0,0,-1) x (0,1,0) = (1,0,0);
  // up' = right x forward = (1,0,0) x (0,0,-1) = (0,1,0).
  const PinholeCamera cam = make_camera({{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90.0f}, 2, 2);
  expect_vec_near(cam.forward(), {0, 0, -1}, kTol);
  expect_vec_near(cam.right(), {1, 0, 0}, kTol);
  expect_vec_near(cam.up(), {0, 1, 0}, kTol);
  EXPECT_EQ(cam.eye(), Vec3(0, 0, 5));
}

TEST(CameraConvention, TwoByTwoPixelsHandChecked) {
  // fovy 90: tan(45) = 1, aspect 1. Pixel (0,0): sx = 2*0.5/2 - 1 = -0.5,
  // sy = 1 - 2*0.5/2 = 0.5, so dir = normalize(-0.5, 0.5, -1)
  // = (-0.40824829, 0.40824829, -0.81649658). Left half has negative right
  // component, the top row (y = 0) positive up component.
  const PinholeCamera cam = make_camera({{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90.0f}, 2, 2);
  const float a = 0.40824829f;
  const float b = 0.81649658f;
  expect_vec_near(cam.ray(0, 0).direction, {-a, a, -b}, kTol);
  expect_vec_near(cam.ray(1, 0).direction, {a, a, -b}, kTol);
  expect_vec_near(cam.ray(0, 1).direction, {-a, -a, -b}, kTol);
  expect_vec_near(cam.ray(1, 1).direction, {a, -a, -b}, kTol);
  const Ray r = cam.ray(0, 0);
  EXPECT_EQ(r.origin, Vec3(0, 0, 5));
  EXPECT_EQ(r.t_min, 0.0f);
  EXPECT_EQ(r.t_max, std::numeric_limits<float>::infinity());
  // The top-left pixel looks up and to the left.
  EXPECT_GT(glm::dot(r.direction, cam.up()), 0.0f);
  EXPECT_LT(glm::dot(r.direction, cam.right()), 0.0f);
}

TEST(CameraConvention, ImageCornersSpanTheFieldOfView) {
  // ray_at takes continuous positions: (0, 0) is the top-left corner, where
  // sx = -1, sy = 1: dir = normalize(-1, 1, -1) for fovy 90, aspect 1.
  const PinholeCamera cam = make_camera({{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90.0f}, 2, 2);
  const float k = 0.57735027f;
  expect_vec_near(cam.ray_at(0.0f, 0.0f).direction, {-k, k, -k}, kTol);
  expect_vec_near(cam.ray_at(2.0f, 2.0f).direction, {k, -k, -k}, kTol);
  expect_vec_near(cam.ray_at(1.0f, 1.0f).direction, {0, 0, -1}, kTol);
}

TEST(CameraConvention, NonSquareAspectHandChecked) {
  // 4x2, fovy 90: aspect 2. Pixel (0,0): sx = 2*0.5/4 - 1 = -0.75, times
  // aspect -> -1.5; sy = 0.5. dir = (-1.5, 0.5, -1)/sqrt(3.5).
  const PinholeCamera cam = make_camera({{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90.0f}, 4, 2);
  const float n = std::sqrt(3.5f);
  expect_vec_near(cam.ray(0, 0).direction, {-1.5f / n, 0.5f / n, -1.0f / n}, kTol);
  EXPECT_EQ(cam.width(), 4);
  EXPECT_EQ(cam.height(), 2);
}

TEST(CameraConvention, RotatedCameraHandChecked) {
  // eye (3,0,0) looking at the origin with up = +z: forward = (-1,0,0),
  // right = (-1,0,0) x (0,0,1) = (0,1,0), up' = (0,1,0) x (-1,0,0) = (0,0,1).
  // 3x1 image, fovy 60: tan 30 = 0.57735027, aspect 3. Pixel (2,0):
  // sx = 2*2.5/3 - 1 = 2/3, sy = 0: right component 2/3 * 0.57735 * 3
  // = 1.15470054; dir = (-1, 1.15470054, 0)/1.52752523.
  const PinholeCamera cam = make_camera({{3, 0, 0}, {0, 0, 0}, {0, 0, 1}, 60.0f}, 3, 1);
  expect_vec_near(cam.right(), {0, 1, 0}, kTol);
  expect_vec_near(cam.up(), {0, 0, 1}, kTol);
  expect_vec_near(cam.ray(2, 0).direction, {-1.0f / 1.52752523f, 1.15470054f / 1.52752523f, 0}, kTol);
  // The centre pixel of an odd-size image looks exactly along forward.
  expect_vec_near(cam.ray(1, 0).direction, cam.forward(), kTol);
}

TEST(CameraConvention, UpNeedNotBeUnitOrOrthogonal) {
  // Only the plane of forward and up matters: up = (0, 7, 3) gives the same
  // basis as (0, 1, 0) for a camera looking along -z.
  const PinholeCamera cam = make_camera({{1, 2, 3}, {1, 2, -7}, {0, 7, 3}, 45.0f}, 5, 3);
  expect_vec_near(cam.forward(), {0, 0, -1}, kTol);
  expect_vec_near(cam.right(), {1, 0, 0}, kTol);
  expect_vec_near(cam.up(), {0, 1, 0}, kTol);
  // Centre pixel of an odd-size image (5x3: pixel (2,1)) looks along forward.
  expect_vec_near(cam.ray(2, 1).direction, {0, 0, -1}, kTol);
}

TEST(CameraConvention, EveryRayIsUnitAndTheBasisOrthonormal) {
  const PinholeCamera cam =
      make_camera({{0.3f, 1.7f, 4.2f}, {-0.5f, 0.9f, 0.1f}, {0.1f, 1, 0.2f}, 35.0f}, 7, 5);
  EXPECT_NEAR(glm::length(cam.forward()), 1.0f, kTol);
  EXPECT_NEAR(glm::length(cam.right()), 1.0f, kTol);
  EXPECT_NEAR(glm::length(cam.up()), 1.0f, kTol);
  EXPECT_NEAR(glm::dot(cam.forward(), cam.right()), 0.0f, kTol);
  EXPECT_NEAR(glm::dot(cam.forward(), cam.up()), 0.0f, kTol);
  EXPECT_NEAR(glm::dot(cam.right(), cam.up()), 0.0f, kTol);
  // Right-handed: right x up' = -forward (camera looks down its -z).
  expect_vec_near(glm::cross(cam.right(), cam.up()), -cam.forward(), kTol);
  const float tan_half = std::tan(35.0f * 3.14159265f / 360.0f);
  for (int y = 0; y < cam.height(); ++y) {
    for (int x = 0; x < cam.width(); ++x) {
      const Vec3 d = cam.ray(x, y).direction;
      EXPECT_NEAR(glm::length(d), 1.0f, kTol);
      // Projected back onto the basis, the direction gives the pixel's screen
      // coordinates of the formula in camera.h.
      const float f = glm::dot(d, cam.forward());
      const float sx = 2.0f * (static_cast<float>(x) + 0.5f) / 7.0f - 1.0f;
      const float sy = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / 5.0f;
      EXPECT_NEAR(glm::dot(d, cam.right()) / f, sx * tan_half * 7.0f / 5.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(d, cam.up()) / f, sy * tan_half, 1e-5f);
    }
  }
}

void expect_invalid(const CameraDesc& desc, int width, int height, const std::string& field,
                    const std::string& value_part) {
  Expected<PinholeCamera> camera = PinholeCamera::create(desc, width, height);
  ASSERT_FALSE(camera.ok()) << field;
  EXPECT_EQ(camera.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(camera.status().field(), field) << camera.status().message();
  EXPECT_NE(std::string(camera.status().value()).find(value_part), std::string::npos)
      << camera.status().message();
}

TEST(CameraErrors, EachBadFieldIsNamedWithItsValue) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const CameraDesc good;
  EXPECT_TRUE(PinholeCamera::create(good, 1, 1).ok());

  CameraDesc d = good;
  d.eye.y = nan;
  expect_invalid(d, 4, 4, "camera.eye", "nan");
  d = good;
  d.target.z = inf;
  expect_invalid(d, 4, 4, "camera.target", "inf");
  d = good;
  d.up.x = -inf;
  expect_invalid(d, 4, 4, "camera.up", "-inf");
  d = good;
  d.target = d.eye;
  expect_invalid(d, 4, 4, "camera.target", "(0, 1, 4)");
  d = good;
  d.up = Vec3(0, 0, 3);  // parallel to forward = (0, 0, -1)
  expect_invalid(d, 4, 4, "camera.up", "(0, 0, 3)");
  d = good;
  d.up = Vec3(0);
  expect_invalid(d, 4, 4, "camera.up", "(0, 0, 0)");
  d = good;
  d.up = Vec3(1e-9f, 0, -1);  // parallel within 1e-9 relative
  expect_invalid(d, 4, 4, "camera.up", "e-10");
  for (float fovy : {0.0f, 180.0f, -10.0f, 200.0f, nan, inf}) {
    d = good;
    d.fovy_degrees = fovy;
    expect_invalid(d, 4, 4, "camera.fovy_degrees", "");
  }
  d = good;
  d.fovy_degrees = 180.0f;
  expect_invalid(d, 4, 4, "camera.fovy_degrees", "180");
  expect_invalid(good, 0, 4, "width", "0");
  expect_invalid(good, 4, -3, "height", "-3");
}

TEST(CameraErrors, TinyButValidInputsAreAccepted) {
  // A tiny up vector and a tiny eye-target distance are still a valid camera.
  const PinholeCamera cam = make_camera({{0, 0, 1e-20f}, {0, 0, 0}, {0, 1e-30f, 0}, 179.0f}, 1, 1);
  expect_vec_near(cam.up(), {0, 1, 0}, kTol);
  expect_vec_near(cam.ray(0, 0).direction, {0, 0, -1}, kTol);
}

}  // namespace
}  // namespace sinew::rt
