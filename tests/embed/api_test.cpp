// The public API (include/sinew/) against the internal renderer it wraps:
// same pixels, only the requested outputs, host pitches, host schedulers,
// host matrices, and errors as values.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <thread>

#include "animation/blend.h"
#include "animation/mixer.h"
#include "animation/pose.h"
#include "runtime/image/texture.h"
#include "runtime/pack/pack_format.h"
#include "tests/embed/api_test_support.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

using testing_support::Frame;
using testing_support::kEveryOutput;
using testing_support::load_mannequin;
using testing_support::mannequin_pack_path;
using testing_support::render_internal;

constexpr int kW = 96;
constexpr int kH = 80;

character::Pack open_mannequin_pack() { return character::Pack::open(mannequin_pack_path()).value(); }

api::RayTracePass make_pass(api::OutputMask outputs, int w = kW, int h = kH) {
  api::PassDesc desc;
  desc.width = w;
  desc.height = h;
  desc.outputs = outputs;
  desc.threads = 2;
  auto pass = api::RayTracePass::create(desc);
  EXPECT_TRUE(pass.ok()) << pass.error().message;
  return std::move(pass).value();
}

api::PassInputs inputs_with(const api::Light& light) {
  api::PassInputs in;
  in.camera = testing_support::test_camera();
  in.lights = std::span<const api::Light>(&light, 1);
  return in;
}

Affine3 to_affine(const api::Matrix3x4& m) {
  Affine3 a;
  for (int r = 0; r < 3; ++r) a.rows[static_cast<std::size_t>(r)] = Vec4(m.m[r][0], m.m[r][1], m.m[r][2], m.m[r][3]);
  return a;
}

api::Matrix3x4 to_api(const Affine3& a) {
  api::Matrix3x4 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m.m[r][c] = a(r, c);
  }
  return m;
}

Affine3 detail_product(const api::Matrix3x4& a, const Affine3& b) { return to_affine(a) * b; }

void expect_same_frame(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.rgba8, b.rgba8);
  EXPECT_EQ(std::memcmp(a.rgba32f.data(), b.rgba32f.data(), a.rgba32f.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(a.instance_id, b.instance_id);
  EXPECT_EQ(a.triangle_id, b.triangle_id);
  EXPECT_EQ(std::memcmp(a.uv.data(), b.uv.data(), a.uv.size() * sizeof(Vec2)), 0);
  EXPECT_EQ(std::memcmp(a.barycentric.data(), b.barycentric.data(), a.barycentric.size() * sizeof(Vec2)), 0);
  EXPECT_EQ(a.material_id, b.material_id);
}

std::size_t hit_pixels(const Frame& f) {
  std::size_t n = 0;
  for (std::uint32_t id : f.triangle_id) n += id != api::kNoHit;
  return n;
}

TEST(ApiVersion, MatchesTheHeadersAndThePackFormat) {
  const api::Version v = api::library_version();
  EXPECT_EQ(v.major, SINEW_VERSION_MAJOR);
  EXPECT_EQ(v.minor, SINEW_VERSION_MINOR);
  EXPECT_EQ(v.patch, SINEW_VERSION_PATCH);
  EXPECT_EQ(api::pack_format_version().major, kPackVersionMajor);
  EXPECT_EQ(api::pack_format_version().minor, kPackVersionMinor);
}

// The mannequin with uvs and its shirt (material 1) textured by a 4x4
// checkerboard of red and blue, as a pack in memory. Each texel spans a
// third of a metre or so: magnified in the test's view, so level 0.
std::vector<std::byte> textured_mannequin_pack() {
  testing_support::BakedModel m = testing_support::idle_mannequin();
  SkinnedMesh& mesh = m.model.mesh;
  for (const Vec3& p : mesh.positions) mesh.uvs.emplace_back(0.6f * p.x, 0.6f * p.y);
  std::vector<float> checker;
  for (int i = 0; i < 16; ++i) {
    const bool red = (i % 4 + i / 4) % 2 == 0;
    checker.insert(checker.end(), {red ? 1.0f : 0.0f, 0.0f, red ? 0.0f : 1.0f, 1.0f});
  }
  mesh.textures = {make_texture("checker", 4, 4, checker, TextureWrap::kRepeat, TextureWrap::kRepeat).value()};
  mesh.material_texture.assign(mesh.material_colors.size(), kNoTexture);
  mesh.material_texture[1] = 0;
  character::PackContents contents;
  contents.model = &m.model;
  contents.fuzzy = &m.bake.fuzzy;
  return character::serialize_pack(contents).value();
}

TEST(ApiCharacter, MaterialsAreNamedAndTexturedMaterialsShadeWithTheirTexture) {
  const std::vector<std::byte> bytes = textured_mannequin_pack();
  const auto c = api::Character::from_memory(bytes, "textured.pack");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const character::Pack pack = open_mannequin_pack();
  ASSERT_EQ(c->material_count(), pack.model().mesh.material_colors.size());
  for (std::size_t m = 0; m < c->material_count(); ++m) {
    EXPECT_EQ(c->material_name(m), m < pack.model().material_names.size() ? pack.model().material_names[m] : "");
    EXPECT_EQ(c->material_has_texture(m), m == 1);
  }
  EXPECT_EQ(c->material_name(c->material_count()), "");
  EXPECT_FALSE(c->material_has_texture(c->material_count()));

  // Through the pass: the shirt's pixels blend the checker's red and blue
  // at their uv (ambient light only: the colour is the albedo times 0.5).
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  ASSERT_TRUE(world->add_instance(*c).ok());
  auto pass = api::RayTracePass::create(
      {.width = kW, .height = kH, .outputs = api::Output::kColorRgba32f | api::Output::kUv | api::Output::kMaterialId});
  ASSERT_TRUE(pass.ok());
  Frame f(kW, kH);
  api::PassInputs inputs;
  inputs.camera = testing_support::test_camera();
  inputs.ambient = {0.5f, 0.5f, 0.5f};
  ASSERT_TRUE(pass->execute(*world, inputs, f.outputs()).ok());
  int shirt = 0, checked = 0, reds = 0;  // reds: pixels mostly red
  for (std::size_t p = 0; p < f.material_id.size(); ++p) {
    if (f.material_id[p] != 1u) continue;
    ++shirt;
    // The bilinear blend of the checker at the pixel's uv, from the
    // definition: texel centres at (i + 0.5) / 4, repeating.
    const float x = f.uv[p].x * 4.0f - 0.5f, y = f.uv[p].y * 4.0f - 0.5f;
    const float x0 = std::floor(x), y0 = std::floor(y);
    float red_share = 0.0f;
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const int tx = static_cast<int>(x0) + dx, ty = static_cast<int>(y0) + dy;
        const bool red = (((tx % 4) + 4) % 4 + ((ty % 4) + 4) % 4) % 2 == 0;
        const float w = (dx ? x - x0 : 1.0f - (x - x0)) * (dy ? y - y0 : 1.0f - (y - y0));
        red_share += red ? w : 0.0f;
      }
    }
    const Vec3 colour = pack.model().mesh.material_colors[1];
    EXPECT_NEAR(f.rgba32f[4 * p], 0.5f * colour.x * red_share, 1e-3f) << "pixel " << p;
    EXPECT_NEAR(f.rgba32f[4 * p + 2], 0.5f * colour.z * (1.0f - red_share), 1e-3f) << "pixel " << p;
    ++checked;
    const bool red = red_share > 0.5f;
    reds += red ? 1 : 0;
  }
  EXPECT_GT(shirt, 200);
  EXPECT_EQ(checked, shirt);
  EXPECT_GT(reds, 10);
  EXPECT_GT(checked - reds, 10);
}

TEST(ApiCharacter, DescribesThePack) {
  const api::Character c = load_mannequin();
  const character::Pack pack = open_mannequin_pack();
  ASSERT_EQ(c.bone_count(), pack.model().skeleton.joint_count());
  for (std::size_t b = 0; b < c.bone_count(); ++b) {
    EXPECT_EQ(c.bone_name(b), pack.model().skeleton.names()[b]);
    EXPECT_EQ(c.bone_parent(b), pack.model().skeleton.parents()[b]);
    EXPECT_EQ(c.find_bone(c.bone_name(b)).value(), b);
    // bind_pose is the inverse of the inverse bind matrix.
    const Affine3 product = detail_product(c.bind_pose(b), pack.model().skeleton.inverse_bind()[b]);
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 4; ++col) EXPECT_NEAR(product(r, col), r == col ? 1.0f : 0.0f, 1e-4f);
    }
  }
  EXPECT_EQ(c.bone_name(c.bone_count()), "");
  EXPECT_EQ(c.bone_parent(c.bone_count()), -1);
  ASSERT_EQ(c.clip_count(), pack.model().clips.size());
  EXPECT_EQ(c.clip_name(0), pack.model().clips[0].name());
  EXPECT_EQ(c.clip_duration(0), pack.model().clips[0].duration());
  EXPECT_EQ(c.triangle_count(), pack.model().mesh.triangle_count());
  EXPECT_EQ(c.vertex_count(), pack.model().mesh.vertex_count());
  const api::Character::Bounds bounds = c.bind_bounds();
  Vec3 lo(1e30f), hi(-1e30f);
  for (const Vec3& p : pack.model().mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  EXPECT_EQ(Vec3(bounds.min.x, bounds.min.y, bounds.min.z), lo);
  EXPECT_EQ(Vec3(bounds.max.x, bounds.max.y, bounds.max.z), hi);
  EXPECT_NE(c.pose_space().find("clip"), std::string::npos) << c.pose_space();
  const auto missing = c.find_bone("no_such_bone");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, api::ErrorCode::kNotFound);
  EXPECT_NE(missing.error().message.find("no_such_bone"), std::string::npos);
}

// --- the pass reproduces the renderer ---------------------------------------

TEST(ApiPass, PoseAtRendersWhatTheRendererRendersForThatClipPose) {
  const api::Character character = load_mannequin();
  const character::Pack pack = open_mannequin_pack();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  const auto id = world->add_instance(character);
  ASSERT_TRUE(id.ok()) << id.error().message;
  ASSERT_TRUE(world->pose_at(*id, "walk", 0.4).ok());

  const api::Light light = testing_support::test_light();
  Frame ours(kW, kH);
  api::RayTracePass pass = make_pass(kEveryOutput);
  const auto stats = pass.execute(*world, inputs_with(light), ours.outputs());
  ASSERT_TRUE(stats.ok()) << stats.error().message;

  const Frame reference = render_internal(pack, {testing_support::clip_pose(pack.model(), "walk", 0.4)}, kW, kH);
  expect_same_frame(ours, reference);
  EXPECT_GT(hit_pixels(ours), 300u);
  EXPECT_EQ(stats->primary_rays, static_cast<std::uint64_t>(kW * kH));
  EXPECT_GT(stats->shadow_rays, 0u);
  // The idle-baked pack does not cover a walk: its escapes are reported,
  // with the time their fallback tree took, a part of the prepare.
  EXPECT_GT(stats->escaped_triangles, 0u);
  EXPECT_GT(stats->fallback_ms, 0.0);
  EXPECT_LE(stats->fallback_ms, stats->prepare_ms);
  // Inside the pose space (the idle clip it was baked over, at a key) nothing
  // escapes and the fallback costs nothing.
  ASSERT_TRUE(world->pose_at(*id, "idle", 0.0).ok());
  const auto idle = pass.execute(*world, inputs_with(light), ours.outputs());
  ASSERT_TRUE(idle.ok()) << idle.error().message;
  EXPECT_EQ(idle->escaped_triangles, 0u);
  EXPECT_EQ(idle->fallback_ms, 0.0);
}

TEST(ApiPass, TheMixerDrivesInstancesLikeTheAnimationSystem) {
  const api::Character character = load_mannequin();
  const character::Pack pack = open_mannequin_pack();
  const character::Model& model = pack.model();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  api::InstanceDesc desc;
  desc.transform = api::Matrix3x4::translation(0.3f, 0.0f, -0.2f);
  const auto id = world->add_instance(character, desc);
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(world->play_cycle(*id, "walk", 1.0f, 0.0f).ok());  // starts the clock
  ASSERT_TRUE(world->play_cycle(*id, "idle", 0.5f, 0.2f).ok());
  ASSERT_TRUE(world->play_action(*id, "wave", 0.1f, 0.1f).ok());
  for (int step = 0; step < 7; ++step) ASSERT_TRUE(world->advance(1.0f / 30.0f).ok());

  // The same schedule on the animation system directly.
  anim::Mixer mixer(model.clips);
  const auto clip = [&](const char* name) { return static_cast<int>(model.find_clip(name) - model.clips.data()); };
  ASSERT_TRUE(mixer.blend_cycle(clip("walk"), 1.0f, 0.0f).ok());
  mixer.update(0.0f);  // what play_cycle on an idle mixer adds to Cal3D's semantics
  ASSERT_TRUE(mixer.blend_cycle(clip("idle"), 0.5f, 0.2f).ok());
  ASSERT_TRUE(mixer.execute_action(clip("wave"), 0.1f, 0.1f).ok());
  std::vector<anim::SamplingCache> caches(model.clips.size());
  const std::size_t joints = model.skeleton.joint_count();
  std::vector<anim::JointTransform> local(joints);
  std::vector<Affine3> model_pose(joints), skin(joints);
  for (int step = 0; step < 7; ++step) mixer.update(1.0f / 30.0f);
  ASSERT_TRUE(anim::evaluate_layers(model.skeleton, model.clips, mixer.layers(), caches, local).ok());
  ASSERT_TRUE(anim::local_to_model(model.skeleton, local, model_pose).ok());
  ASSERT_TRUE(anim::skinning_matrices(model.skeleton, model_pose, to_affine(desc.transform), skin).ok());

  const api::Light light = testing_support::test_light();
  Frame ours(kW, kH);
  api::RayTracePass pass = make_pass(kEveryOutput);
  ASSERT_TRUE(pass.execute(*world, inputs_with(light), ours.outputs()).ok());
  expect_same_frame(ours, render_internal(pack, {skin}, kW, kH));
}

TEST(ApiPass, HostMatricesRenderTheSameAsTheMixerAtThatPose) {
  const api::Character character = load_mannequin();
  const character::Pack pack = open_mannequin_pack();
  const std::vector<Affine3> pose = testing_support::clip_pose(pack.model(), "kick", 0.55);
  std::vector<api::Matrix3x4> host(pose.size());
  for (std::size_t b = 0; b < pose.size(); ++b) host[b] = to_api(pose[b]);

  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  api::InstanceDesc host_driven;
  host_driven.driver = api::Driver::kHost;
  const auto hosted = world->add_instance(character, host_driven);
  ASSERT_TRUE(hosted.ok());
  ASSERT_TRUE(world->set_bone_matrices(*hosted, host).ok());

  auto mixer_world = api::World::create();
  ASSERT_TRUE(mixer_world.ok());
  const auto mixed = mixer_world->add_instance(character);
  ASSERT_TRUE(mixed.ok());
  ASSERT_TRUE(mixer_world->pose_at(*mixed, "kick", 0.55).ok());

  const api::Light light = testing_support::test_light();
  api::RayTracePass pass = make_pass(kEveryOutput);
  Frame a(kW, kH), b(kW, kH);
  ASSERT_TRUE(pass.execute(*world, inputs_with(light), a.outputs()).ok());
  ASSERT_TRUE(pass.execute(*mixer_world, inputs_with(light), b.outputs()).ok());
  expect_same_frame(a, b);
  EXPECT_GT(hit_pixels(a), 300u);
}

// PassInputs' ray masks reach the renderer: an instance whose mask shares
// no bit with camera_ray_mask is not drawn, and the rest of the image is
// the same as with that instance removed from camera rays alone (its
// shadow stays: shadow_ray_mask still takes it).
TEST(ApiPass, CameraRayMaskLeavesAnInstanceUndrawnButShadowing) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  api::InstanceDesc left, right;
  left.transform = api::Matrix3x4::translation(-0.45f, 0.0f, 0.0f);
  right.transform = api::Matrix3x4::translation(0.45f, 0.0f, 0.0f);
  right.mask = 2u;
  const auto a = world->add_instance(character, left);
  const auto b = world->add_instance(character, right);
  ASSERT_TRUE(a.ok() && b.ok());
  const api::Float3 quad[] = {{-3, 0, -3}, {3, 0, -3}, {-3, 0, 3}, {3, 0, 3}};
  const std::uint32_t indices[] = {0, 2, 1, 1, 2, 3};
  ASSERT_TRUE(world->add_static_mesh({quad, indices, {0.5f, 0.5f, 0.5f}}).ok());
  const api::Light light = testing_support::test_light();
  api::RayTracePass pass = make_pass(api::Output::kColorRgba32f | api::Output::kInstanceId);
  Frame all(kW, kH), masked(kW, kH), masked_everywhere(kW, kH);
  api::PassInputs inputs = inputs_with(light);
  ASSERT_TRUE(pass.execute(*world, inputs, all.outputs()).ok());
  inputs.camera_ray_mask = ~2u;
  ASSERT_TRUE(pass.execute(*world, inputs, masked.outputs()).ok());
  inputs.shadow_ray_mask = ~2u;
  ASSERT_TRUE(pass.execute(*world, inputs, masked_everywhere.outputs()).ok());
  const auto count = [](const Frame& f, std::uint32_t id) { return std::count(f.instance_id.begin(), f.instance_id.end(), id); };
  EXPECT_GT(count(all, *b), 100);
  EXPECT_EQ(count(masked, *b), 0);
  EXPECT_GT(count(masked, *a), 100);
  // Its shadow on the ground stays until shadow rays leave it out too.
  EXPECT_NE(masked.rgba32f, masked_everywhere.rgba32f);
}

TEST(ApiPass, InstancesShareTheirCharacterAndStaticMeshesJoinTheNumbering) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  const auto first = world->add_instance(character);
  const api::Float3 quad[] = {{-3, 0, -3}, {3, 0, -3}, {-3, 0, 3}, {3, 0, 3}};
  const std::uint32_t indices[] = {0, 2, 1, 1, 2, 3};
  const auto ground = world->add_static_mesh({quad, indices, {0.5f, 0.5f, 0.5f}});
  api::InstanceDesc moved;
  moved.transform = api::Matrix3x4::translation(0.8f, 0.0f, 0.0f);
  const auto second = world->add_instance(character, moved);
  ASSERT_TRUE(first.ok() && ground.ok() && second.ok());
  EXPECT_EQ(*first, 0u);
  EXPECT_EQ(*ground, 1u);
  EXPECT_EQ(*second, 2u);
  EXPECT_EQ(world->instance_count(), 3u);

  const api::Light light = testing_support::test_light();
  Frame f(kW, kH);
  api::RayTracePass pass = make_pass(kEveryOutput);
  ASSERT_TRUE(pass.execute(*world, inputs_with(light), f.outputs()).ok());
  std::size_t seen[3] = {0, 0, 0};
  for (std::uint32_t id : f.instance_id) {
    if (id != api::kNoHit) {
      ASSERT_LT(id, 3u);
      ++seen[id];
    }
  }
  EXPECT_GT(seen[0], 100u);
  EXPECT_GT(seen[1], 100u);
  EXPECT_GT(seen[2], 100u);
}

// --- outputs: only what was asked, at the host's pitch ----------------------

TEST(ApiPass, WritesOnlyTheRequestedOutputs) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  ASSERT_TRUE(world->add_instance(character).ok());
  const api::Light light = testing_support::test_light();

  Frame all(kW, kH);
  ASSERT_TRUE(make_pass(kEveryOutput).execute(*world, inputs_with(light), all.outputs()).ok());

  for (const api::Output only :
       {api::Output::kColorRgba8, api::Output::kColorRgba32f, api::Output::kDepth, api::Output::kNormal,
        api::Output::kInstanceId, api::Output::kTriangleId, api::Output::kUv, api::Output::kBarycentrics,
        api::Output::kMaterialId}) {
    SCOPED_TRACE(static_cast<int>(only));
    Frame f(kW, kH);
    // Sentinels everywhere: the outputs not asked for must keep them.
    std::fill(f.rgba8.begin(), f.rgba8.end(), std::uint8_t{0xAB});
    std::fill(f.rgba32f.begin(), f.rgba32f.end(), -7.0f);
    std::fill(f.depth.begin(), f.depth.end(), -7.0f);
    std::fill(f.normal.begin(), f.normal.end(), Vec3(-7.0f));
    std::fill(f.instance_id.begin(), f.instance_id.end(), 0xABABABABu);
    std::fill(f.triangle_id.begin(), f.triangle_id.end(), 0xABABABABu);
    std::fill(f.uv.begin(), f.uv.end(), Vec2(-7.0f));
    std::fill(f.barycentric.begin(), f.barycentric.end(), Vec2(-7.0f));
    std::fill(f.material_id.begin(), f.material_id.end(), 0xABABABABu);
    ASSERT_TRUE(make_pass(only).execute(*world, inputs_with(light), f.outputs()).ok());
    const bool rgba8 = only == api::Output::kColorRgba8, rgba32f = only == api::Output::kColorRgba32f;
    const bool depth = only == api::Output::kDepth, normal = only == api::Output::kNormal;
    const bool instance = only == api::Output::kInstanceId, triangle = only == api::Output::kTriangleId;
    EXPECT_EQ(f.rgba8 == all.rgba8, rgba8);
    EXPECT_EQ(f.rgba32f == all.rgba32f, rgba32f);
    EXPECT_EQ(f.depth == all.depth, depth);
    EXPECT_EQ(f.normal == all.normal, normal);
    EXPECT_EQ(f.instance_id == all.instance_id, instance);
    EXPECT_EQ(f.triangle_id == all.triangle_id, triangle);
    EXPECT_EQ(f.uv == all.uv, only == api::Output::kUv);
    EXPECT_EQ(f.barycentric == all.barycentric, only == api::Output::kBarycentrics);
    EXPECT_EQ(f.material_id == all.material_id, only == api::Output::kMaterialId);
    if (!rgba8) {
      EXPECT_TRUE(std::all_of(f.rgba8.begin(), f.rgba8.end(), [](std::uint8_t v) { return v == 0xAB; }));
    }
    if (!depth) {
      EXPECT_TRUE(std::all_of(f.depth.begin(), f.depth.end(), [](float v) { return v == -7.0f; }));
    }
  }
}

// A host buffer with padded rows, filled with a sentinel byte.
struct PitchedBuffer {
  std::vector<std::byte> bytes;
  std::size_t pitch;
  PitchedBuffer(std::size_t row_bytes, int height, std::size_t padding)
      : bytes((row_bytes + padding) * static_cast<std::size_t>(height), std::byte{0x5A}), pitch(row_bytes + padding) {}
};

TEST(ApiPass, RowPitchesPlaceRowsAndNeverTouchThePadding) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  ASSERT_TRUE(world->add_instance(character).ok());
  const api::Light light = testing_support::test_light();
  Frame packed(kW, kH);
  ASSERT_TRUE(make_pass(kEveryOutput).execute(*world, inputs_with(light), packed.outputs()).ok());

  // Pitches as a GPU upload heap would pick (256-byte rows), and odd ones.
  const std::size_t w = kW;
  PitchedBuffer rgba8(4 * w, kH, 256 - (4 * w) % 256 + 1);  // any byte count is fine for RGBA8
  PitchedBuffer rgba32f(16 * w, kH, 64);
  PitchedBuffer depth(4 * w, kH, 256 - (4 * w) % 256);
  PitchedBuffer normal(12 * w, kH, 4);  // not a multiple of 12: only float alignment matters
  PitchedBuffer instance(4 * w, kH, 8);
  PitchedBuffer triangle(4 * w, kH, 12);
  PitchedBuffer uv(8 * w, kH, 4);
  PitchedBuffer barycentrics(8 * w, kH, 64);
  PitchedBuffer material(4 * w, kH, 20);
  api::PassOutputs out;
  out.color_rgba8 = {rgba8.bytes.data(), rgba8.pitch};
  out.color_rgba32f = {rgba32f.bytes.data(), rgba32f.pitch};
  out.depth = {depth.bytes.data(), depth.pitch};
  out.normal = {normal.bytes.data(), normal.pitch};
  out.instance_id = {instance.bytes.data(), instance.pitch};
  out.triangle_id = {triangle.bytes.data(), triangle.pitch};
  out.uv = {uv.bytes.data(), uv.pitch};
  out.barycentrics = {barycentrics.bytes.data(), barycentrics.pitch};
  out.material_id = {material.bytes.data(), material.pitch};
  const auto done = make_pass(kEveryOutput).execute(*world, inputs_with(light), out);
  ASSERT_TRUE(done.ok()) << done.error().message;

  const auto check = [&](const PitchedBuffer& buffer, const void* reference, std::size_t row_bytes, const char* name) {
    SCOPED_TRACE(name);
    for (int y = 0; y < kH; ++y) {
      const std::byte* row = buffer.bytes.data() + static_cast<std::size_t>(y) * buffer.pitch;
      ASSERT_EQ(std::memcmp(row, static_cast<const std::byte*>(reference) + static_cast<std::size_t>(y) * row_bytes,
                            row_bytes),
                0)
          << "row " << y;
      for (std::size_t pad = row_bytes; pad < buffer.pitch; ++pad) ASSERT_EQ(row[pad], std::byte{0x5A});
    }
  };
  check(rgba8, packed.rgba8.data(), 4 * w, "rgba8");
  check(rgba32f, packed.rgba32f.data(), 16 * w, "rgba32f");
  check(depth, packed.depth.data(), 4 * w, "depth");
  check(normal, packed.normal.data(), 12 * w, "normal");
  check(instance, packed.instance_id.data(), 4 * w, "instance_id");
  check(triangle, packed.triangle_id.data(), 4 * w, "triangle_id");
  check(uv, packed.uv.data(), 8 * w, "uv");
  check(barycentrics, packed.barycentric.data(), 8 * w, "barycentrics");
  check(material, packed.material_id.data(), 4 * w, "material_id");
}

// --- threads: the host's scheduler --------------------------------------------

// A host "thread pool": each batch is spread over `threads` std::threads
// pulling indices from a shared counter.
struct HostPool {
  int threads = 3;
  std::atomic<int> batches{0};
  std::atomic<long> tasks{0};

  static void run_batch(void* user, std::uint32_t count, api::TaskFunction task, void* context) {
    auto* pool = static_cast<HostPool*>(user);
    pool->batches.fetch_add(1);
    std::atomic<std::uint32_t> next{0};
    const auto worker = [&] {
      for (std::uint32_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
        task(context, i);
        pool->tasks.fetch_add(1);
      }
    };
    std::vector<std::thread> workers;
    for (int t = 1; t < pool->threads; ++t) workers.emplace_back(worker);
    worker();
    for (std::thread& t : workers) t.join();
  }
};

TEST(ApiPass, AHostSchedulerRunsTheWorkAndGivesTheSameImage) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  for (int i = 0; i < 3; ++i) {
    api::InstanceDesc desc;
    desc.transform = api::Matrix3x4::translation(0.7f * static_cast<float>(i - 1), 0.0f, 0.0f);
    const auto id = world->add_instance(character, desc);
    ASSERT_TRUE(id.ok());
    ASSERT_TRUE(world->play_cycle(*id, i == 1 ? "run" : "walk", 1.0f, 0.0f).ok());
  }
  ASSERT_TRUE(world->advance(0.3f).ok());
  const api::Light light = testing_support::test_light();
  api::RayTracePass pass = make_pass(kEveryOutput);
  Frame tbb(kW, kH), hosted(kW, kH);
  ASSERT_TRUE(pass.execute(*world, inputs_with(light), tbb.outputs()).ok());

  HostPool pool;
  const api::TaskScheduler scheduler{pool.threads, &pool, &HostPool::run_batch};
  const auto stats = pass.execute(*world, inputs_with(light), hosted.outputs(), &scheduler);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  expect_same_frame(tbb, hosted);
  EXPECT_GE(pool.batches.load(), 2);  // at least the skinning and the tiles
  // The pass renders 32x32-pixel tiles (RenderSettings::tile_size), one task each.
  EXPECT_GE(pool.tasks.load(), static_cast<long>((kW / 32) * (kH / 32)));
}

// --- lights -------------------------------------------------------------------

TEST(ApiPass, LightsAddUpAndNoLightsLeaveAmbientOnly) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  ASSERT_TRUE(world->add_instance(character).ok());
  api::Light key = testing_support::test_light();
  api::Light rim;
  rim.kind = api::Light::Kind::kDirectional;
  rim.direction = {-1.0f, 0.5f, 0.4f};
  rim.color = {0.3f, 0.4f, 0.9f};
  api::RayTracePass pass = make_pass(api::Output::kColorRgba32f | api::Output::kNormal);

  const auto render = [&](std::span<const api::Light> lights) {
    Frame f(kW, kH);
    api::PassInputs in;
    in.camera = testing_support::test_camera();
    in.lights = lights;
    EXPECT_TRUE(pass.execute(*world, in, f.outputs()).ok());
    return f;
  };
  const api::Light both[] = {key, rim};
  const Frame none = render({});
  const Frame only_key = render(std::span<const api::Light>(&key, 1));
  const Frame only_rim = render(std::span<const api::Light>(&rim, 1));
  const Frame sum = render(both);
  std::size_t lit_by_rim = 0;
  for (std::size_t i = 0; i < sum.pixels(); ++i) {
    for (std::size_t c = 0; c < 3; ++c) {
      // albedo * (ambient + a + b) against the parts: linear up to rounding.
      const float expected = only_key.rgba32f[4 * i + c] + only_rim.rgba32f[4 * i + c] - none.rgba32f[4 * i + c];
      const bool background = sum.normal[i] == Vec3(0.0f);
      if (background) {
        EXPECT_EQ(sum.rgba32f[4 * i + c], none.rgba32f[4 * i + c]);
      } else {
        ASSERT_NEAR(sum.rgba32f[4 * i + c], expected, 1e-5f) << "pixel " << i;
      }
    }
    if (only_rim.rgba32f[4 * i + 2] > none.rgba32f[4 * i + 2] + 1e-3f) ++lit_by_rim;
  }
  EXPECT_GT(lit_by_rim, 100u);

  api::Light too_many[api::kMaxLights + 1];
  api::PassInputs in;
  in.camera = testing_support::test_camera();
  in.lights = too_many;
  Frame f(kW, kH);
  const auto refused = pass.execute(*world, in, f.outputs());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, api::ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.error().message.find("inputs.lights"), std::string::npos);
}

}  // namespace
}  // namespace sinew
