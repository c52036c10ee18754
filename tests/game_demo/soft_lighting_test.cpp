// The demo's soft shadows and ambient occlusion: the options (--soft and
// the four values, each refused by name and value when bad), and a session
// that renders with them: a sphere light changes the picture and takes its
// samples, ambient occlusion only darkens, and the lights given by --light
// take the radius too.
#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "game_demo/demo_options.h"
#include "game_demo/demo_session.h"
#include "game_demo/soft_lighting.h"
#include "runtime/jobs/job_system.h"

namespace sinew::demo {
namespace {

TEST(DemoSoftLighting, OffByDefaultAndTheSoftPresetSizedByTheCharacters) {
  const auto d = parse_demo_options({});
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->soft.light_radius, 0.0f) << "hard point light by default";
  EXPECT_EQ(d->soft.ao_rays, 0) << "no ambient occlusion by default";
  EXPECT_EQ(d->soft.shadow_samples, 4);
  EXPECT_FLOAT_EQ(d->soft.ao_radius, 0.9f);

  const auto soft = parse_demo_options({"--soft"});
  ASSERT_TRUE(soft.ok()) << soft.status().message();
  EXPECT_EQ(soft->soft, soft_preset());
  EXPECT_FLOAT_EQ(soft_preset().light_radius, 0.3f * kCharacterHeight);
  EXPECT_EQ(soft_preset().shadow_samples, 4);
  EXPECT_EQ(soft_preset().ao_rays, 4);
  EXPECT_FLOAT_EQ(soft_preset().ao_radius, 0.5f * kCharacterHeight);
  // The help tells the preset's figures as they are.
  EXPECT_NE(demo_usage().find("sphere light of radius 0.54 m"), std::string::npos) << demo_usage();
}

TEST(DemoSoftLighting, EachOptionSetsItsValueOverThePreset) {
  const auto o = parse_demo_options(
      {"--light-radius", "0.25", "--shadow-samples", "16", "--ao-rays=8", "--ao-radius", "1.5"});
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->soft.light_radius, 0.25f);
  EXPECT_EQ(o->soft.shadow_samples, 16);
  EXPECT_EQ(o->soft.ao_rays, 8);
  EXPECT_EQ(o->soft.ao_radius, 1.5f);

  // The preset with its ambient occlusion turned off, and with a hard light.
  const auto no_ao = parse_demo_options({"--soft", "--ao-rays", "0"});
  ASSERT_TRUE(no_ao.ok()) << no_ao.status().message();
  EXPECT_EQ(no_ao->soft.ao_rays, 0);
  EXPECT_EQ(no_ao->soft.light_radius, soft_preset().light_radius);
  const auto hard = parse_demo_options({"--soft", "--light-radius", "0"});
  ASSERT_TRUE(hard.ok()) << hard.status().message();
  EXPECT_EQ(hard->soft.light_radius, 0.0f);
  EXPECT_EQ(hard->soft.ao_rays, 4);
}

TEST(DemoSoftLighting, BadValuesNameTheOptionAndTheValue) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--light-radius", "-0.1"}, "--light-radius = -0.1: expected a number from 0 to 1000"},
      {{"--light-radius", "nan"}, "--light-radius = nan: expected a number"},
      {{"--light-radius", "2000"}, "--light-radius = 2000: expected a number from 0 to 1000"},
      {{"--shadow-samples", "0"}, "--shadow-samples = 0: expected an integer from 1 to 256"},
      {{"--shadow-samples", "300"}, "--shadow-samples = 300: expected an integer from 1 to 256"},
      {{"--ao-rays", "-1"}, "--ao-rays = -1: expected an integer from 0 to 256"},
      {{"--ao-rays", "lots"}, "--ao-rays = lots: expected an integer"},
      {{"--ao-radius", "0"}, "--ao-radius = 0: expected a length above 0"},
      {{"--ao-radius", "-1"}, "--ao-radius = -1: expected a number from 0 to 1000"},
      {{"--soft", "--ao-radius", "x"}, "--ao-radius = x: expected a number"},
      {{"--ao-rays"}, "--ao-rays"},
  };
  for (const auto& [args, message] : cases) {
    const auto parsed = parse_demo_options(args);
    ASSERT_FALSE(parsed.ok()) << message;
    EXPECT_NE(parsed.status().message().find(message), std::string::npos)
        << "expected '" << message << "' in: " << parsed.status().message();
  }
}

std::vector<std::uint8_t> render_still(DemoSession& session, JobSystem& jobs, float dt, rt::RenderStats* stats) {
  FollowCamera camera;
  auto report = session.frame(dt, PlayerInput{}, camera, jobs);
  EXPECT_TRUE(report.ok()) << report.status().message();
  if (report.ok() && stats != nullptr) *stats = report->render;
  return {session.rgba().begin(), session.rgba().end()};
}

// One frame three ways (the world stepped by 0 s after the first): hard,
// with the preset's sphere light, and with ambient occlusion alone.
TEST(DemoSoftLighting, TheSessionRendersSoftShadowsAndAmbientOcclusion) {
  JobSystem jobs(2);
  SessionOptions options;
  options.width = 96;
  options.height = 96;
  options.characters = 3;
  auto created = DemoSession::create(options, jobs);
  ASSERT_TRUE(created.ok()) << created.status().message();
  DemoSession& session = **created;
  EXPECT_EQ(session.render_settings().ao_rays, 0);
  EXPECT_EQ(session.render_settings().light.radius, 0.0f);

  rt::RenderStats hard_stats, soft_stats, ao_stats;
  const auto hard = render_still(session, jobs, 1.0f / 30.0f, &hard_stats);
  SoftLighting soft = soft_preset();
  soft.ao_rays = 0;
  session.set_soft_lighting(soft);
  EXPECT_EQ(session.render_settings().light.radius, soft.light_radius);
  const auto softened = render_still(session, jobs, 0.0f, &soft_stats);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < hard.size(); ++i) differ += hard[i] != softened[i];
  EXPECT_GT(differ, 30u);
  EXPECT_GT(soft_stats.shadow_rays, 3 * hard_stats.shadow_rays) << "4 samples per lit hit";
  EXPECT_EQ(soft_stats.ao_rays, 0u);

  soft.light_radius = 0.0f;
  soft.ao_rays = 4;
  session.set_soft_lighting(soft);
  const auto occluded = render_still(session, jobs, 0.0f, &ao_stats);
  std::size_t darker = 0, brighter = 0;
  for (std::size_t i = 0; i < hard.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    darker += occluded[i] < hard[i];
    brighter += occluded[i] > hard[i];
  }
  EXPECT_GT(darker, 100u);
  EXPECT_EQ(brighter, 0u) << "occlusion scales the ambient light down, never up";
  EXPECT_GT(ao_stats.ao_rays, 0u);
  EXPECT_EQ(ao_stats.shadow_rays, hard_stats.shadow_rays) << "a hard light again";
  bool timed = false;
  for (const auto& [phase, ms] : session.timers().latest()) timed = timed || phase == "trace ao";
  EXPECT_TRUE(timed) << "the ambient occlusion rays have their own phase";
}

// Lights given with --light: the point lights take the radius, the
// directional ones stay hard.
TEST(DemoSoftLighting, GivenPointLightsTakeTheRadius) {
  JobSystem jobs(1);
  SessionOptions options;
  options.width = 16;
  options.height = 16;
  options.characters = 1;
  options.lights.resize(2);
  options.lights[1].kind = rt::Light::Kind::kDirectional;
  options.soft.light_radius = 0.4f;
  auto created = DemoSession::create(options, jobs);
  ASSERT_TRUE(created.ok()) << created.status().message();
  const std::span<const rt::Light> lights = (*created)->render_settings().lights;
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].radius, 0.4f);
  EXPECT_EQ(lights[1].radius, 0.0f);
  EXPECT_EQ(lights[1].angular_radius, 0.0f);
}

}  // namespace
}  // namespace sinew::demo
