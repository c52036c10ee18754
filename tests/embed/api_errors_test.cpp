// The public API's errors: values that say what was wrong, never an
// exception, a crash, or a half-written output.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "tests/embed/api_test_support.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

using testing_support::Frame;
using testing_support::kEveryOutput;
using testing_support::mannequin_pack_path;

void expect_error(const api::Status& s, api::ErrorCode code, const std::string& mentions) {
  ASSERT_FALSE(s.ok()) << "expected an error mentioning " << mentions;
  EXPECT_EQ(s.error().code, code) << s.error().message;
  EXPECT_NE(s.error().message.find(mentions), std::string::npos) << s.error().message;
}

template <class T>
void expect_error(const api::Result<T>& r, api::ErrorCode code, const std::string& mentions) {
  expect_error(r.status(), code, mentions);
}

std::vector<std::byte> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(chars.size());
  std::memcpy(bytes.data(), chars.data(), chars.size());
  return bytes;
}

TEST(ApiErrors, LoadingNamesTheFileAndWhatIsWrong) {
  expect_error(api::Character::load("/no/such/dir/x.pack"), api::ErrorCode::kNotFound, "/no/such/dir/x.pack");

  std::vector<std::byte> bytes = read_bytes(mannequin_pack_path());
  ASSERT_GT(bytes.size(), 1000u);
  ASSERT_TRUE(api::Character::from_memory(bytes, "copy.pack").ok());
  // A flipped byte in the middle: the checksum catches it.
  std::vector<std::byte> damaged = bytes;
  damaged[damaged.size() / 2] ^= std::byte{0x40};
  expect_error(api::Character::from_memory(damaged, "damaged.pack"), api::ErrorCode::kCorruptData, "damaged.pack");
  // Truncated.
  expect_error(api::Character::from_memory(std::span(bytes).first(bytes.size() / 3), "short.pack"),
               api::ErrorCode::kCorruptData, "short.pack");
  // Not a pack at all.
  const std::byte junk[64] = {};
  expect_error(api::Character::from_memory(junk, "junk.pack"), api::ErrorCode::kCorruptData, "junk.pack");
}

TEST(ApiErrors, AModelOnlyPackIsRefusedWithTheCommandThatBakesIt) {
  const testing_support::BakedModel& baked = testing_support::idle_mannequin();
  character::PackContents contents;
  contents.model = &baked.model;  // no fuzzy trees
  const auto bytes = character::serialize_pack(contents);
  ASSERT_TRUE(bytes.ok());
  expect_error(api::Character::from_memory(*bytes, "model-only.pack"), api::ErrorCode::kUnsupported,
               "sinew-editor bake");
}

class ApiWorldErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    auto c = api::Character::load(mannequin_pack_path());
    ASSERT_TRUE(c.ok()) << c.error().message;
    character_ = std::make_unique<api::Character>(std::move(c).value());
    auto w = api::World::create();
    ASSERT_TRUE(w.ok());
    world_ = std::make_unique<api::World>(std::move(w).value());
    mixed_ = world_->add_instance(*character_).value();
    api::InstanceDesc host;
    host.driver = api::Driver::kHost;
    hosted_ = world_->add_instance(*character_, host).value();
  }
  std::unique_ptr<api::Character> character_;
  std::unique_ptr<api::World> world_;
  api::InstanceId mixed_ = 0;
  api::InstanceId hosted_ = 0;
};

TEST_F(ApiWorldErrors, BoneMatricesAreCheckedBeforeAnythingChanges) {
  std::vector<api::Matrix3x4> bones(character_->bone_count());
  ASSERT_TRUE(world_->set_bone_matrices(hosted_, bones).ok());
  expect_error(world_->set_bone_matrices(hosted_, std::span(bones).first(bones.size() - 1)),
               api::ErrorCode::kInvalidArgument, "bones");
  bones[3].m[1][2] = std::numeric_limits<float>::quiet_NaN();
  expect_error(world_->set_bone_matrices(hosted_, bones), api::ErrorCode::kInvalidArgument,
               "skinning[3] (bone '" + std::string(character_->bone_name(3)) + "')");
  bones[3].m[1][2] = std::numeric_limits<float>::infinity();
  expect_error(world_->set_bone_matrices(hosted_, bones), api::ErrorCode::kInvalidArgument, "not finite");
  expect_error(world_->set_bone_matrices(mixed_, bones), api::ErrorCode::kInvalidArgument, "mixer-driven");
  expect_error(world_->set_bone_matrices(99, bones), api::ErrorCode::kNotFound, "instance 99");
}

TEST_F(ApiWorldErrors, MixerCallsNameTheClipAndTheInstance) {
  expect_error(world_->play_cycle(mixed_, "moonwalk", 1.0f, 0.0f), api::ErrorCode::kNotFound, "'moonwalk'");
  expect_error(world_->play_cycle(mixed_, "moonwalk", 1.0f, 0.0f), api::ErrorCode::kNotFound, "walk");  // lists clips
  expect_error(world_->play_cycle(mixed_, "#99", 1.0f, 0.0f), api::ErrorCode::kNotFound, "#99");
  expect_error(world_->play_cycle(mixed_, "walk", -1.0f, 0.0f), api::ErrorCode::kInvalidArgument, "weight");
  expect_error(world_->play_cycle(mixed_, "walk", 1.0f, std::numeric_limits<float>::quiet_NaN()),
               api::ErrorCode::kInvalidArgument, "delay");
  expect_error(world_->play_cycle(hosted_, "walk", 1.0f, 0.0f), api::ErrorCode::kInvalidArgument, "host-driven");
  expect_error(world_->play_action(mixed_, "wave", -0.1f, 0.1f), api::ErrorCode::kInvalidArgument, "fade");
  expect_error(world_->pose_at(mixed_, "walk", std::numeric_limits<double>::infinity()),
               api::ErrorCode::kInvalidArgument, "seconds");
  expect_error(world_->advance(-1.0f), api::ErrorCode::kInvalidArgument, "dt_seconds");
  api::Matrix3x4 bad;
  bad.m[0][0] = std::numeric_limits<float>::infinity();
  expect_error(world_->set_transform(mixed_, bad), api::ErrorCode::kInvalidArgument, "model_to_world");
  api::InstanceDesc desc;
  desc.transform = bad;
  expect_error(world_->add_instance(*character_, desc), api::ErrorCode::kInvalidArgument, "transform");
  ASSERT_TRUE(world_->play_cycle(mixed_, "#1", 1.0f, 0.0f).ok());  // by index
  ASSERT_TRUE(world_->advance(0.1f).ok());
}

TEST_F(ApiWorldErrors, StaticMeshesAreChecked) {
  const api::Float3 p[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::uint32_t two[] = {0, 1};
  const std::uint32_t past[] = {0, 1, 3};
  expect_error(world_->add_static_mesh({p, two, {}}), api::ErrorCode::kInvalidArgument, "multiple of 3");
  expect_error(world_->add_static_mesh({p, past, {}}), api::ErrorCode::kInvalidArgument, "indices[2]: 3");
  const api::Float3 nan[] = {{0, 0, 0}, {1, std::numeric_limits<float>::quiet_NaN(), 0}, {0, 1, 0}};
  const std::uint32_t tri[] = {0, 1, 2};
  expect_error(world_->add_static_mesh({nan, tri, {}}), api::ErrorCode::kInvalidArgument, "positions[1]");
  EXPECT_TRUE(world_->add_static_mesh({p, tri, {}}).ok());
}

TEST(ApiPassErrors, DescriptionsAreChecked) {
  api::PassDesc desc;
  desc.width = 0;
  expect_error(api::RayTracePass::create(desc), api::ErrorCode::kInvalidArgument, "0x1024");
  desc.width = 64;
  desc.outputs = api::OutputMask();
  expect_error(api::RayTracePass::create(desc), api::ErrorCode::kInvalidArgument, "desc.outputs");
  desc.outputs = api::OutputMask(1u << 20);
  expect_error(api::RayTracePass::create(desc), api::ErrorCode::kInvalidArgument, "desc.outputs");
  desc.outputs = api::Output::kDepth | api::Output::kTriangleId;
  auto pass = api::RayTracePass::create(desc);
  ASSERT_TRUE(pass.ok());
  // Declared resources: the five inputs, then the two outputs asked for.
  const auto resources = pass->resources();
  ASSERT_EQ(resources.size(), 7u);
  EXPECT_STREQ(resources[0].name, "bone_matrices");
  EXPECT_FALSE(resources[0].optional);
  EXPECT_STREQ(resources[3].name, "static_geometry");
  EXPECT_TRUE(resources[3].optional);
  EXPECT_STREQ(resources[4].name, "gbuffer");
  EXPECT_TRUE(resources[4].optional);
  EXPECT_STREQ(resources[5].name, "depth");
  EXPECT_EQ(resources[5].access, api::ResourceDecl::Access::kWrite);
  EXPECT_EQ(resources[5].bytes_per_pixel, 4u);
  EXPECT_STREQ(resources[6].name, "triangle_id");
}

TEST(ApiPassErrors, BadOutputsAndInputsWriteNothing) {
  auto character = api::Character::load(mannequin_pack_path());
  ASSERT_TRUE(character.ok());
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  ASSERT_TRUE(world->add_instance(*character).ok());
  api::PassDesc desc;
  desc.width = 40;
  desc.height = 30;
  desc.outputs = kEveryOutput;
  auto pass = api::RayTracePass::create(desc);
  ASSERT_TRUE(pass.ok());
  api::PassInputs inputs;
  inputs.camera = testing_support::test_camera();

  Frame f(40, 30);
  std::fill(f.rgba8.begin(), f.rgba8.end(), std::uint8_t{7});
  const auto untouched = [&] { return std::all_of(f.rgba8.begin(), f.rgba8.end(), [](std::uint8_t v) { return v == 7; }); };

  api::PassOutputs out = f.outputs();
  out.normal.data = nullptr;
  expect_error(pass->execute(*world, inputs, out), api::ErrorCode::kInvalidArgument, "outputs.normal.data");
  EXPECT_TRUE(untouched());

  out = f.outputs();
  out.depth.row_pitch = 4 * 40 - 4;  // shorter than a row
  expect_error(pass->execute(*world, inputs, out), api::ErrorCode::kInvalidArgument, "row_pitch.depth");
  EXPECT_TRUE(untouched());
  out.depth.row_pitch = 4 * 40 + 2;  // rows would start mid-float
  expect_error(pass->execute(*world, inputs, out), api::ErrorCode::kInvalidArgument, "alignment");
  EXPECT_TRUE(untouched());

  api::PassInputs bad_camera = inputs;
  bad_camera.camera.target = bad_camera.camera.eye;
  expect_error(pass->execute(*world, bad_camera, f.outputs()), api::ErrorCode::kInvalidArgument, "inputs.camera");
  bad_camera = inputs;
  bad_camera.camera.fovy_degrees = 180.0f;
  expect_error(pass->execute(*world, bad_camera, f.outputs()), api::ErrorCode::kInvalidArgument, "fovy");
  api::Light nan_light;
  nan_light.position.y = std::numeric_limits<float>::quiet_NaN();
  api::PassInputs bad_light = inputs;
  bad_light.lights = std::span<const api::Light>(&nan_light, 1);
  expect_error(pass->execute(*world, bad_light, f.outputs()), api::ErrorCode::kInvalidArgument, "inputs.lights[0]");
  EXPECT_TRUE(untouched());

  const api::TaskScheduler no_callback{2, nullptr, nullptr};
  expect_error(pass->execute(*world, inputs, f.outputs(), &no_callback), api::ErrorCode::kInvalidArgument,
               "run_batch");
  EXPECT_TRUE(untouched());
  ASSERT_TRUE(pass->execute(*world, inputs, f.outputs()).ok());
  EXPECT_FALSE(untouched());
}

TEST(ApiResult, HoldsAValueOrAnError) {
  api::Result<int> good = 3;
  EXPECT_TRUE(good.ok());
  EXPECT_EQ(*good, 3);
  EXPECT_TRUE(good.status().ok());
  api::Result<int> bad = api::Error{api::ErrorCode::kNotFound, "x"};
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, api::ErrorCode::kNotFound);
  EXPECT_EQ(bad.status().error().message, "x");
  EXPECT_DEATH((void)bad.value(), "");
}

}  // namespace
}  // namespace sinew
