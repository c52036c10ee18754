// Soft shadows and ambient occlusion through the renderer: a pixel's light
// is its unshadowed light times the fraction of its samples that reach it
// (a multiple of 1/n, with penumbrae between 0 and 1); nothing in the way
// gives the hard light's image, bit for bit; images are the same for any
// thread count and tile size; bad sampling settings are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "tests/raytrace/render_test_support.h"

namespace sinew {
namespace {

using testing_support::scene;

constexpr int kWidth = 64, kHeight = 48;

rt::PinholeCamera test_camera() {
  return rt::PinholeCamera::create({Vec3(0.5f, 1.6f, 3.2f), Vec3(0.0f, 0.5f, 0.0f), Vec3(0, 1, 0), 55.0f}, kWidth,
                                   kHeight)
      .value();
}

struct Masks {
  std::vector<float> shadow, ambient_occlusion;
};

std::vector<float> render_linear(const rt::Scene& sc, const rt::RenderSettings& settings, int threads = 2,
                                 Masks* masks = nullptr) {
  JobSystem jobs(threads);
  std::vector<float> rgba(4 * static_cast<std::size_t>(kWidth * kHeight));
  rt::FrameBuffers buffers;
  buffers.width = kWidth;
  buffers.height = kHeight;
  buffers.color_rgba32f = rgba;
  if (masks) {
    masks->shadow.assign(static_cast<std::size_t>(kWidth * kHeight), -1.0f);
    masks->ambient_occlusion.assign(static_cast<std::size_t>(kWidth * kHeight), -1.0f);
    buffers.shadow = masks->shadow;
    buffers.ambient_occlusion = masks->ambient_occlusion;
  }
  const auto stats = rt::Renderer().render(sc, test_camera(), settings, buffers, jobs);
  EXPECT_TRUE(stats.ok()) << stats.status().message();
  return rgba;
}

rt::RenderSettings sphere_light(int samples) {
  rt::RenderSettings settings;
  settings.light.position = Vec3(1.0f, 2.5f, 1.5f);
  settings.light.radius = 0.8f;
  settings.shadow_samples = samples;
  settings.ambient = Vec3(0.0f);
  return settings;
}

TEST(SoftShadows, APixelsLightIsItsUnshadowedLightTimesTheFractionOfSamplesThatReachIt) {
  const rt::Scene& sc = scene();
  for (const int samples : {4, 16}) {
    rt::RenderSettings settings = sphere_light(samples);
    Masks masks;
    const std::vector<float> soft = render_linear(sc, settings, 2, &masks);
    settings.shadows = false;
    const std::vector<float> open = render_linear(sc, settings);
    std::set<int> fractions;
    for (std::size_t p = 0; p < soft.size(); p += 4) {
      if (open[p] < 1e-3f) continue;
      const float fraction = soft[p] / open[p];
      const float k = std::round(fraction * static_cast<float>(samples));
      ASSERT_NEAR(fraction, k / static_cast<float>(samples), 1e-4f) << "pixel " << p / 4;
      ASSERT_GE(k, 0.0f);
      ASSERT_LE(k, static_cast<float>(samples));
      for (int c = 1; c < 3; ++c) ASSERT_NEAR(soft[p + c], fraction * open[p + c], 1e-5f);
      // The shadow mask holds the fraction; without ambient occlusion rays
      // the ambient occlusion mask is 1.
      ASSERT_EQ(masks.shadow[p / 4], k / static_cast<float>(samples)) << "pixel " << p / 4;
      ASSERT_EQ(masks.ambient_occlusion[p / 4], 1.0f);
      fractions.insert(static_cast<int>(k));
    }
    // Umbra, penumbra and open light all appear.
    EXPECT_TRUE(fractions.count(0));
    EXPECT_TRUE(fractions.count(samples));
    EXPECT_GE(fractions.size(), static_cast<std::size_t>(samples / 2)) << "a penumbra of many steps";
  }
}

TEST(SoftShadows, NothingInTheWayGivesTheHardLightsImage) {
  // The ground alone, lit from high above: every sample reaches it.
  rt::Scene ground;
  rt::StaticMeshDesc quad;
  quad.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  quad.triangles = {{0, 2, 1}, {1, 2, 3}};
  ASSERT_TRUE(ground.add_static_mesh(quad).ok());
  JobSystem jobs(2);
  ASSERT_TRUE(ground.prepare_frame(rt::FrameOptions{}, jobs).ok());
  rt::RenderSettings hard;
  hard.light.position = Vec3(0.5f, 6.0f, 0.5f);
  hard.ambient = Vec3(0.2f);
  const std::vector<float> reference = render_linear(ground, hard);
  rt::RenderSettings sphere = hard;
  sphere.light.radius = 1.0f;
  EXPECT_EQ(render_linear(ground, sphere), reference);
  rt::RenderSettings rect = hard;
  rect.light.kind = rt::Light::Kind::kRect;
  rect.light.edge_u = Vec3(2.0f, 0.0f, 0.0f);
  rect.light.edge_v = Vec3(0.0f, 0.0f, 1.0f);
  EXPECT_EQ(render_linear(ground, rect), reference);
  rt::RenderSettings sun = hard;
  sun.light.kind = rt::Light::Kind::kDirectional;
  sun.light.direction = Vec3(0.2f, 1.0f, 0.1f);
  const std::vector<float> sun_reference = render_linear(ground, sun);
  sun.light.angular_radius = 0.1f;
  EXPECT_EQ(render_linear(ground, sun), sun_reference);
  // Ambient occlusion with nothing near: every ray escapes.
  rt::RenderSettings ao = hard;
  ao.ao_rays = 8;
  ao.ao_radius = 2.0f;
  EXPECT_EQ(render_linear(ground, ao), reference);
}

TEST(SoftShadows, AmbientOcclusionDarkensOnlyTheAmbientTermNearOccluders) {
  const rt::Scene& sc = scene();
  rt::RenderSettings settings;
  settings.light.color = Vec3(0.0f);
  settings.ambient = Vec3(1.0f);
  const std::vector<float> open = render_linear(sc, settings);
  settings.ao_rays = 8;
  settings.ao_radius = 0.4f;
  Masks masks;
  const std::vector<float> occluded = render_linear(sc, settings, 2, &masks);
  std::size_t darker = 0, same = 0;
  for (std::size_t p = 0; p < open.size(); p += 4) {
    if (open[p] < 1e-3f) continue;
    const float fraction = occluded[p] / open[p];
    const float k = std::round(fraction * 8.0f);
    ASSERT_NEAR(fraction, k / 8.0f, 1e-4f);
    ASSERT_EQ(masks.ambient_occlusion[p / 4], k / 8.0f);
    (k < 8.0f ? darker : same) += 1;
  }
  EXPECT_GT(darker, 50u);  // the mannequins' creases and the ground at their feet
  EXPECT_GT(same, 100u);    // the open ground
}

TEST(SoftShadows, ImagesAreTheSameForAnyThreadCountAndTileSize) {
  const rt::Scene& sc = scene();
  rt::RenderSettings settings = sphere_light(4);
  settings.ao_rays = 4;
  settings.ao_radius = 0.5f;
  settings.ambient = Vec3(0.3f);
  const std::vector<float> reference = render_linear(sc, settings, 2);
  EXPECT_EQ(render_linear(sc, settings, 1), reference);
  settings.tile_size = 16;
  EXPECT_EQ(render_linear(sc, settings, 2), reference);
  settings.sample_seed = 1;
  EXPECT_NE(render_linear(sc, settings, 2), reference) << "the seed changes the pattern";
}

TEST(SoftShadows, BadSamplingSettingsAreRefusedByName) {
  const rt::Scene& sc = scene();
  JobSystem jobs(1);
  std::vector<float> rgba(4 * static_cast<std::size_t>(kWidth * kHeight));
  rt::FrameBuffers buffers;
  buffers.width = kWidth;
  buffers.height = kHeight;
  buffers.color_rgba32f = rgba;
  const auto refused = [&](const rt::RenderSettings& settings, const std::string& field) {
    const auto result = rt::Renderer().render(sc, test_camera(), settings, buffers, jobs);
    ASSERT_FALSE(result.ok()) << field;
    EXPECT_EQ(result.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(result.status().message().find(field), std::string::npos) << result.status().message();
  };
  rt::RenderSettings s;
  s.shadow_samples = 0;
  refused(s, "shadow_samples");
  s.shadow_samples = rt::kMaxSamples + 1;
  refused(s, "shadow_samples");
  s = {};
  for (const int steps : {-1, 1, 2, 3, 24, rt::kMaxSphereDiskSteps * 2}) {
    s.sphere_disk_steps = steps;
    refused(s, "sphere_disk_steps");
  }
  s = {};
  s.ao_rays = -1;
  refused(s, "ao_rays");
  s.ao_rays = 4;
  s.ao_radius = 0.0f;
  refused(s, "ao_radius");
  s.ao_radius = std::nanf("");
  refused(s, "ao_radius");
  s = {};
  s.light.radius = -1.0f;
  refused(s, "radius");
  s.light.radius = std::numeric_limits<float>::infinity();
  refused(s, "radius");
  s = {};
  s.light.kind = rt::Light::Kind::kDirectional;
  s.light.angular_radius = 2.0f;
  refused(s, "angular_radius");
  s = {};
  s.light.kind = rt::Light::Kind::kRect;
  s.light.edge_u = Vec3(1.0f, 0.0f, 0.0f);
  s.light.edge_v = Vec3(2.0f, 0.0f, 0.0f);
  refused(s, "edge_u");
  s = {};
  s.light.position = Vec3(std::nanf(""), 0.0f, 0.0f);
  refused(s, "lights[0]");
}

}  // namespace
}  // namespace sinew
