// FrameCull (scene/visibility.h) against rays: a box on a camera ray is in
// view, and a box on a shadow ray (from a light to a receiver point that a
// camera ray reaches) casts into view, for random cameras, point and
// directional lights and receivers; boxes far from every ray are culled.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "raytrace/scene/visibility.h"

namespace sinew {
namespace {

float uniform(std::mt19937& g, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(g() >> 8) * 0x1.0p-24f;
}

Vec3 random_vec(std::mt19937& g, float extent) {
  return {uniform(g, -extent, extent), uniform(g, -extent, extent), uniform(g, -extent, extent)};
}

// A camera at `eye` looking at `target`, with the pinhole basis of camera/camera.h.
rt::FrameVisibility view_from(const Vec3& eye, const Vec3& target, float half_width, float half_height) {
  rt::FrameVisibility view;
  view.eye = eye;
  view.forward = glm::normalize(target - eye);
  view.right = glm::normalize(glm::cross(view.forward, Vec3(0, 1, 0)));
  view.up = glm::cross(view.right, view.forward);
  view.half_width = half_width;
  view.half_height = half_height;
  return view;
}

// Where the ray o + t d (t >= 0) first enters `box` (slab test, double), or
// a negative value.
double entry(const Vec3& o, const Vec3& d, const Aabb& box) {
  double t0 = 0.0, t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) {
      if (o[a] < box.lower[a] || o[a] > box.upper[a]) return -1.0;
      continue;
    }
    const double oa = static_cast<double>(o[a]), da = static_cast<double>(d[a]);
    double lo = (static_cast<double>(box.lower[a]) - oa) / da;
    double hi = (static_cast<double>(box.upper[a]) - oa) / da;
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  return t0 <= t1 ? t0 : -1.0;
}

Aabb box_around(const Vec3& p, float half) { return {p - Vec3(half), p + Vec3(half)}; }

TEST(FrameCull, BoxesOnCameraAndShadowRaysAreKept) {
  std::mt19937 g(53);
  int shadow_boxes = 0, culled = 0;
  for (int scene = 0; scene < 200; ++scene) {
    const Vec3 eye = random_vec(g, 20.0f);
    const rt::FrameVisibility base =
        view_from(eye, eye + random_vec(g, 1.0f) + Vec3(0.0f, 0.0f, 0.01f), uniform(g, 0.05f, 2.0f),
                  uniform(g, 0.05f, 2.0f));
    rt::FrameVisibility view = base;
    view.light_count = 1 + static_cast<std::uint32_t>(g() % 2);
    for (std::uint32_t l = 0; l < view.light_count; ++l) {
      view.lights[l].kind = g() % 2 ? rt::ViewLight::Kind::kPoint : rt::ViewLight::Kind::kDirectional;
      view.lights[l].position = random_vec(g, 30.0f);
      view.lights[l].direction = random_vec(g, 1.0f) + Vec3(0.0f, 0.01f, 0.0f);
    }
    // Receivers: a wide flat ground and a few boxes.
    Aabb receivers[4] = {{Vec3(-40.0f, -0.1f, -40.0f), Vec3(40.0f, 0.0f, 40.0f)}};
    for (int r = 1; r < 4; ++r) receivers[r] = box_around(random_vec(g, 15.0f), uniform(g, 0.2f, 3.0f));
    rt::FrameCull cull;
    ASSERT_TRUE(cull.begin(view, 60.0f));
    for (const Aabb& box : receivers) cull.add_receivers(box);
    cull.finish_receivers();
    for (int ray = 0; ray < 100; ++ray) {
      const float a = uniform(g, -base.half_width, base.half_width);
      const float b = uniform(g, -base.half_height, base.half_height);
      const Vec3 d = glm::normalize(base.forward + a * base.right + b * base.up);
      // A box anywhere along the camera ray is in view.
      const Vec3 on_ray = eye + uniform(g, 0.0f, 50.0f) * d;
      EXPECT_TRUE(cull.in_view(box_around(on_ray, 0.01f))) << scene << " " << ray;
      // The nearest receiver hit starts shadow rays.
      double t = 1e30;
      for (const Aabb& box : receivers) {
        const double e = entry(eye, d, box);
        if (e >= 0.0) t = std::min(t, e);
      }
      if (t >= 1e29) continue;
      const Vec3 p = eye + static_cast<float>(t) * d;
      for (std::uint32_t l = 0; l < view.light_count; ++l) {
        const rt::ViewLight& light = view.lights[l];
        const float s = uniform(g, 0.0f, 1.0f);
        const Vec3 q = light.kind == rt::ViewLight::Kind::kPoint
                           ? light.position + s * (p - light.position)
                           : p + uniform(g, 0.0f, 100.0f) * glm::normalize(light.direction);
        const Aabb caster = box_around(q, 0.01f);
        EXPECT_TRUE(cull.in_view(caster) || cull.casts_into_view(caster)) << scene << " " << ray << " " << l;
        ++shadow_boxes;
      }
    }
    // Far boxes: some are culled (the cull does something), none wrongly,
    // which the rays above check.
    for (int far = 0; far < 20; ++far) {
      const Aabb box = box_around(random_vec(g, 200.0f), 0.5f);
      if (!cull.in_view(box) && !cull.casts_into_view(box)) ++culled;
    }
  }
  EXPECT_GT(shadow_boxes, 5000);
  EXPECT_GT(culled, 400);
}

TEST(FrameCull, WithoutShadowsOnlyTheFrustumKeeps) {
  rt::FrameVisibility view = view_from(Vec3(0, 1, 5), Vec3(0, 1, 0), 0.4f, 0.4f);
  view.shadows = false;
  view.light_count = 1;
  rt::FrameCull cull;
  ASSERT_TRUE(cull.begin(view, 10.0f));
  cull.add_receivers({Vec3(-10, -0.1f, -10), Vec3(10, 0, 10)});
  cull.finish_receivers();
  EXPECT_TRUE(cull.in_view(box_around(Vec3(0, 1, 0), 0.5f)));
  EXPECT_FALSE(cull.in_view(box_around(Vec3(0, 1, 8), 0.5f)));   // behind the eye
  EXPECT_FALSE(cull.in_view(box_around(Vec3(6, 1, 0), 0.5f)));   // right of the view
  EXPECT_FALSE(cull.casts_into_view(box_around(Vec3(6, 1, 0), 0.5f)));
  EXPECT_TRUE(cull.in_view(box_around(Vec3(0, 1, 5), 0.1f)));     // around the eye
}

TEST(FrameCull, AnUnusableViewCullsNothing) {
  rt::FrameVisibility view = view_from(Vec3(0, 1, 5), Vec3(0, 1, 0), 0.4f, 0.4f);
  rt::FrameCull cull;
  view.half_width = 0.0f;
  EXPECT_FALSE(cull.begin(view, 10.0f));
  view.half_width = 0.4f;
  view.eye.x = std::nanf("");
  EXPECT_FALSE(cull.begin(view, 10.0f));
  view.eye.x = 0.0f;
  view.light_count = 1;
  view.lights[0].kind = rt::ViewLight::Kind::kDirectional;
  view.lights[0].direction = Vec3(0.0f);
  EXPECT_FALSE(cull.begin(view, 10.0f));
  view.light_count = rt::kMaxViewLights + 1;
  EXPECT_FALSE(cull.begin(view, 10.0f));
}

}  // namespace
}  // namespace sinew
