// The pass's soft shadows, ambient occlusion and visibility masks through
// the public API: the masks are the internal renderer's, from the camera
// and from a host's G-buffer (a ground the host rasterised, not in the
// World); the G-buffer mode writes only the masks; bad lights, sample
// counts and G-buffers are refused by name, writing nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "tests/embed/api_test_support.h"

namespace sinew {
namespace {

using testing_support::load_mannequin;
using testing_support::mannequin_pack_path;

constexpr int kW = 48;
constexpr int kH = 40;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

template <class R>
void expect_error(const R& result, const std::string& needle) {
  ASSERT_FALSE(result.ok()) << needle;
  EXPECT_EQ(result.error().code, api::ErrorCode::kInvalidArgument);
  EXPECT_NE(result.error().message.find(needle), std::string::npos) << result.error().message;
}

api::RayTracePass make_pass(api::OutputMask outputs) {
  api::PassDesc desc;
  desc.width = kW;
  desc.height = kH;
  desc.outputs = outputs;
  desc.threads = 2;
  auto pass = api::RayTracePass::create(desc);
  EXPECT_TRUE(pass.ok()) << pass.error().message;
  return std::move(pass).value();
}

// A sphere light above the mannequin's right, and a hard one.
std::vector<api::Light> test_lights() {
  api::Light sphere;
  sphere.position = {1.0f, 2.5f, 1.5f};
  sphere.radius = 0.6f;
  api::Light hard;
  hard.position = {2.0f, 4.0f, 3.0f};
  return {sphere, hard};
}
std::vector<rt::Light> internal_lights() {
  std::vector<rt::Light> lights;
  for (const api::Light& in : test_lights()) {
    rt::Light l;
    l.position = Vec3(in.position.x, in.position.y, in.position.z);
    l.radius = in.radius;
    lights.push_back(l);
  }
  return lights;
}

// The host's ground: pixel (x, y) at (-1.5 + 3 (x + 1/2) / W, 0, -1.5 + 3 (y
// + 1/2) / H), normal up; column 0 is sky (no position).
struct HostGround {
  std::vector<api::Float3> position, normal;
  HostGround() : position(kW * kH), normal(kW * kH, api::Float3{0.0f, 1.0f, 0.0f}) {
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        position[static_cast<std::size_t>(y * kW + x)] =
            x == 0 ? api::Float3{kNaN, kNaN, kNaN}
                   : api::Float3{-1.5f + 3.0f * (static_cast<float>(x) + 0.5f) / kW, 0.0f,
                                 -1.5f + 3.0f * (static_cast<float>(y) + 0.5f) / kH};
      }
    }
  }
  api::GBufferInputs inputs(float normal_offset) const {
    api::GBufferInputs g;
    g.position = {position.data(), 0};
    g.normal = {normal.data(), 0};
    g.normal_offset = normal_offset;
    return g;
  }
};

struct Masks {
  std::vector<float> shadow = std::vector<float>(2 * kW * kH, -1.0f);
  std::vector<float> ambient_occlusion = std::vector<float>(kW * kH, -1.0f);
  api::PassOutputs outputs() {
    api::PassOutputs o;
    o.shadow_mask = {shadow.data(), 0};
    o.ambient_occlusion = {ambient_occlusion.data(), 0};
    return o;
  }
  rt::FrameBuffers buffers() {
    rt::FrameBuffers b;
    b.width = kW;
    b.height = kH;
    b.shadow = shadow;
    b.ambient_occlusion = ambient_occlusion;
    return b;
  }
};

struct MannequinScene {
  api::Character character = load_mannequin();
  api::World world = api::World::create().value();
  std::vector<api::Light> lights = test_lights();
  // The same mannequin in the internal scene, the reference.
  character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  rt::Scene scene;

  MannequinScene() {
    const auto id = world.add_instance(character);
    EXPECT_TRUE(id.ok());
    EXPECT_TRUE(world.pose_at(*id, "idle", 0.0).ok());
    const auto c = scene.add_character(pack.model().mesh, pack.fuzzy());
    const auto instance = scene.add_instance(*c);
    EXPECT_TRUE(scene.set_bones(*instance, testing_support::clip_pose(pack.model(), "idle", 0.0)).ok());
    JobSystem jobs(2);
    EXPECT_TRUE(scene.prepare_frame({}, jobs).ok());
  }
  api::PassInputs inputs() const {
    api::PassInputs in;
    in.camera = testing_support::test_camera();
    in.lights = lights;
    in.shadow_samples = 8;
    in.ao_rays = 4;
    in.ao_radius = 0.4f;
    in.sample_seed = 3;
    return in;
  }
  rt::RenderSettings settings(const std::vector<rt::Light>& rt_lights) const {
    rt::RenderSettings s;
    s.lights = rt_lights;
    s.shadow_samples = 8;
    s.ao_rays = 4;
    s.ao_radius = 0.4f;
    s.sample_seed = 3;
    return s;
  }
};

TEST(ApiMasks, TheCameraModesMasksAreTheRenderers) {
  MannequinScene setup;
  Masks ours;
  api::RayTracePass pass = make_pass(api::Output::kShadowMask | api::Output::kAmbientOcclusion);
  const auto stats = pass.execute(setup.world, setup.inputs(), ours.outputs());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_GT(stats->ao_rays, 0u);

  Masks reference;
  const std::vector<rt::Light> lights = internal_lights();
  const auto camera = rt::PinholeCamera::create(testing_support::test_camera_internal(), kW, kH).value();
  JobSystem jobs(2);
  ASSERT_TRUE(rt::Renderer().render(setup.scene, camera, setup.settings(lights), reference.buffers(), jobs).ok());
  EXPECT_EQ(ours.shadow, reference.shadow);
  EXPECT_EQ(ours.ambient_occlusion, reference.ambient_occlusion);
  EXPECT_LT(*std::min_element(ours.shadow.begin(), ours.shadow.end()), 1.0f) << "the mannequin shadows itself";
}

TEST(ApiMasks, AHostsGroundReceivesTheCharactersSoftShadow) {
  MannequinScene setup;
  const HostGround ground;
  api::PassInputs inputs = setup.inputs();
  inputs.gbuffer = ground.inputs(1e-3f);
  inputs.camera.target = inputs.camera.eye;  // no camera is needed, so a bad one is not read
  Masks ours;
  api::RayTracePass pass = make_pass(api::Output::kShadowMask | api::Output::kAmbientOcclusion);
  const auto stats = pass.execute(setup.world, inputs, ours.outputs());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->primary_rays, 0u);

  // The internal renderer on the same surfaces gives the same masks.
  Masks reference;
  rt::HostSurfaces surfaces;
  surfaces.width = kW;
  surfaces.height = kH;
  static_assert(sizeof(api::Float3) == sizeof(Vec3));
  surfaces.position = {reinterpret_cast<const Vec3*>(ground.position.data()), ground.position.size()};
  surfaces.normal = {reinterpret_cast<const Vec3*>(ground.normal.data()), ground.normal.size()};
  surfaces.normal_offset = 1e-3f;
  const std::vector<rt::Light> lights = internal_lights();
  JobSystem jobs(2);
  ASSERT_TRUE(
      rt::Renderer().render_visibility(setup.scene, surfaces, setup.settings(lights), reference.buffers(), jobs).ok());
  EXPECT_EQ(ours.shadow, reference.shadow);
  EXPECT_EQ(ours.ambient_occlusion, reference.ambient_occlusion);

  // The sphere light's mask (channel 0) steps in eighths, with umbra,
  // penumbra and open ground; the sky column is 1 everywhere.
  std::set<float> sphere_values;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * kW + x);
      const float sphere = ours.shadow[2 * p];
      EXPECT_EQ(sphere * 8.0f, std::round(sphere * 8.0f));
      sphere_values.insert(sphere);
      if (x == 0) {
        EXPECT_EQ(sphere, 1.0f);
        EXPECT_EQ(ours.shadow[2 * p + 1], 1.0f);
        EXPECT_EQ(ours.ambient_occlusion[p], 1.0f);
      }
    }
  }
  EXPECT_TRUE(sphere_values.count(0.0f) && sphere_values.count(1.0f));
  EXPECT_GE(sphere_values.size(), 4u) << "a penumbra";
  EXPECT_LT(*std::min_element(ours.ambient_occlusion.begin(), ours.ambient_occlusion.end()), 1.0f)
      << "the ground at the feet";
}

TEST(ApiMasks, BadLightsSamplesAndGBuffersAreRefusedByNameWritingNothing) {
  MannequinScene setup;
  const HostGround ground;
  Masks masks;
  const auto untouched = [&] {
    return std::all_of(masks.shadow.begin(), masks.shadow.end(), [](float v) { return v == -1.0f; }) &&
           std::all_of(masks.ambient_occlusion.begin(), masks.ambient_occlusion.end(),
                       [](float v) { return v == -1.0f; });
  };
  api::RayTracePass pass = make_pass(api::Output::kShadowMask | api::Output::kAmbientOcclusion);
  const auto refused = [&](const api::PassInputs& in, const std::string& needle) {
    expect_error(pass.execute(setup.world, in, masks.outputs()), needle);
    EXPECT_TRUE(untouched()) << needle;
  };
  const api::PassInputs good = setup.inputs();
  api::PassInputs in = good;
  in.shadow_samples = 0;
  refused(in, "inputs.shadow_samples = 0");
  in = good;
  in.ao_rays = 257;
  refused(in, "inputs.ao_rays = 257");
  in = good;
  in.ao_radius = 0.0f;
  refused(in, "inputs.ao_radius");
  std::vector<api::Light> lights = test_lights();
  in = good;
  in.lights = lights;
  lights[0].radius = -1.0f;
  refused(in, "inputs.lights[0].radius");
  lights[0] = test_lights()[0];
  lights[1].kind = api::Light::Kind::kDirectional;
  lights[1].angular_radius = 2.0f;
  refused(in, "inputs.lights[1].angular_radius");
  lights[1].kind = api::Light::Kind::kRect;
  lights[1].angular_radius = 0.0f;
  lights[1].edge_u = {1.0f, 0.0f, 0.0f};
  lights[1].edge_v = {2.0f, 0.0f, 0.0f};
  refused(in, "inputs.lights[1].edge_u");
  in = good;
  in.lights = {};
  refused(in, "inputs.lights is empty");

  in = good;
  in.gbuffer = ground.inputs(-1.0f);
  in.gbuffer.normal.data = nullptr;
  refused(in, "inputs.gbuffer.normal.data");
  in.gbuffer = ground.inputs(std::numeric_limits<float>::infinity());
  refused(in, "inputs.gbuffer.normal_offset");
  in.gbuffer = ground.inputs(-1.0f);
  in.gbuffer.position.row_pitch = 6;
  refused(in, "inputs.gbuffer.position.row_pitch = 6");
  in.gbuffer = ground.inputs(-1.0f);
  in.gbuffer.normal.row_pitch = kW * 12 + 2;
  refused(in, "inputs.gbuffer.normal.row_pitch");

  // The G-buffer mode writes only the masks.
  api::RayTracePass color = make_pass(api::Output::kColorRgba8 | api::Output::kShadowMask);
  std::vector<std::uint8_t> rgba(4 * kW * kH);
  api::PassOutputs out = masks.outputs();
  out.color_rgba8 = {rgba.data(), 0};
  in.gbuffer = ground.inputs(-1.0f);
  expect_error(color.execute(setup.world, in, out), "color_rgba8");
  EXPECT_TRUE(untouched());
  ASSERT_TRUE(pass.execute(setup.world, in, masks.outputs()).ok());
  EXPECT_FALSE(untouched());
}

}  // namespace
}  // namespace sinew
