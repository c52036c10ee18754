// The game-side animation calls of the public API: each instance's own
// clock (time offset, playback speed, Cal3D's time factor) and the bones'
// world transforms read back for attachments. The references are other
// instances driven the plain way and the animation module's own sampling,
// never the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "animation/clip.h"
#include "animation/pose.h"
#include "tests/embed/api_test_support.h"

namespace sinew {
namespace {

using testing_support::load_mannequin;
using testing_support::mannequin_pack_path;

Affine3 to_affine(const api::Matrix3x4& m) {
  Affine3 a;
  for (int r = 0; r < 3; ++r) a.rows[static_cast<std::size_t>(r)] = Vec4(m.m[r][0], m.m[r][1], m.m[r][2], m.m[r][3]);
  return a;
}

// Every bone's world transform of the instance.
std::vector<api::Matrix3x4> bones_of(const api::World& world, api::InstanceId id, std::size_t count) {
  std::vector<api::Matrix3x4> out;
  for (std::size_t b = 0; b < count; ++b) {
    const auto m = world.bone_transform(id, b);
    EXPECT_TRUE(m.ok()) << m.error().message;
    out.push_back(m.ok() ? *m : api::Matrix3x4{});
  }
  return out;
}

bool same_bits(const std::vector<api::Matrix3x4>& a, const std::vector<api::Matrix3x4>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        if (a[i].m[r][c] != b[i].m[r][c]) return false;
      }
    }
  }
  return true;
}

float max_difference(const Affine3& a, const Affine3& b) {
  float d = 0.0f;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(a(r, c) - b(r, c)));
  }
  return d;
}

// An instance of the mannequin walking (weight 1, `fade` seconds in).
api::InstanceId walker(api::World& world, const api::Character& character, const api::InstanceDesc& desc = {},
                       float fade = 0.0f) {
  const auto id = world.add_instance(character, desc);
  EXPECT_TRUE(id.ok()) << id.error().message;
  EXPECT_TRUE(world.play_cycle(*id, "walk", 1.0f, fade).ok());
  return *id;
}

TEST(ApiAnimation, AnInstanceOffsetByT0PosesAsOneAdvancedT0Further) {
  const api::Character character = load_mannequin();
  const std::size_t bones = character.bone_count();
  constexpr float kT0 = 0.37f;
  // A crowd of two on one clip: one offset, one not.
  auto crowd = api::World::create();
  ASSERT_TRUE(crowd.ok());
  const api::InstanceId offset = walker(*crowd, character, {}, 0.3f);
  const api::InstanceId plain = walker(*crowd, character, {}, 0.3f);
  ASSERT_TRUE(crowd->offset_time(offset, kT0).ok());
  ASSERT_TRUE(crowd->advance(0.1f).ok());
  // The reference: a lone walker the world advanced by t0 first.
  auto alone = api::World::create();
  ASSERT_TRUE(alone.ok());
  const api::InstanceId reference = walker(*alone, character, {}, 0.3f);
  ASSERT_TRUE(alone->advance(kT0).ok());
  ASSERT_TRUE(alone->advance(0.1f).ok());

  EXPECT_TRUE(same_bits(bones_of(*crowd, offset, bones), bones_of(*alone, reference, bones)));
  // Not in lockstep: the other walker is t0 behind.
  EXPECT_FALSE(same_bits(bones_of(*crowd, offset, bones), bones_of(*crowd, plain, bones)));
}

TEST(ApiAnimation, SpeedTwoPlaysAsDoubleStepsAndSpeedZeroHolds) {
  const api::Character character = load_mannequin();
  const std::size_t bones = character.bone_count();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  api::InstanceDesc fast;
  fast.playback_speed = 2.0f;
  const api::InstanceId doubled = walker(*world, character, fast, 0.4f);  // the fade runs at speed too
  const api::InstanceId slow = walker(*world, character, {}, 0.4f);
  auto reference_world = api::World::create();
  ASSERT_TRUE(reference_world.ok());
  const api::InstanceId reference = walker(*reference_world, character, {}, 0.4f);
  for (int step = 0; step < 5; ++step) {
    ASSERT_TRUE(world->advance(0.05f).ok());
    ASSERT_TRUE(reference_world->advance(0.1f).ok());
    EXPECT_TRUE(same_bits(bones_of(*world, doubled, bones), bones_of(*reference_world, reference, bones))) << step;
  }
  EXPECT_FALSE(same_bits(bones_of(*world, doubled, bones), bones_of(*world, slow, bones)));

  ASSERT_TRUE(world->set_playback_speed(slow, 0.0f).ok());
  const std::vector<api::Matrix3x4> held = bones_of(*world, slow, bones);
  ASSERT_TRUE(world->advance(0.25f).ok());
  EXPECT_TRUE(same_bits(bones_of(*world, slow, bones), held));
}

TEST(ApiAnimation, TimeFactorRunsTheSyncClock) {
  const api::Character character = load_mannequin();
  const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  const character::Model& model = pack.model();
  const anim::Skeleton& skeleton = model.skeleton;
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  const api::InstanceId id = walker(*world, character);
  ASSERT_TRUE(world->set_time_factor(id, 2.5f).ok());
  ASSERT_TRUE(world->advance(0.2f).ok());

  // Hand-checked: one cycle at full weight is the walk sampled on its own
  // at 2.5 x 0.2 = 0.5 s of the sync clock.
  const anim::Clip& walk = *model.find_clip("walk");
  std::vector<anim::JointTransform> local(skeleton.joint_count());
  std::vector<Affine3> expected(skeleton.joint_count());
  ASSERT_TRUE(anim::rest_pose(skeleton, local).ok());
  anim::SamplingCache cache;
  anim::sample_clip(walk, anim::clip_time(walk, 0.5, /*loop=*/true), cache, local);
  ASSERT_TRUE(anim::local_to_model(skeleton, local, expected).ok());
  for (std::size_t b = 0; b < skeleton.joint_count(); ++b) {
    EXPECT_LT(max_difference(to_affine(world->bone_transform(id, b).value()), expected[b]), 1e-5f) << b;
  }
  // That fades keep real time is the mixer's (tests/animation/mixer_test.cpp).
}

TEST(ApiAnimation, TheHandBoneIsTheSkeletonsJointMatrixPlacedInTheWorld) {
  const api::Character character = load_mannequin();
  const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  const character::Model& model = pack.model();
  const anim::Skeleton& skeleton = model.skeleton;
  const std::size_t hand = character.find_bone("hand_r").value();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  api::InstanceDesc desc;
  // A quarter turn about Y and a step: the placement shows in the result.
  desc.transform = api::Matrix3x4{{{0.0f, 0.0f, 1.0f, 2.0f}, {0.0f, 1.0f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f, -1.5f}}};
  const auto id = world->add_instance(character, desc);
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(world->pose_at(*id, "walk", 0.45).ok());

  // The animation module alone: sample, local to model, then the placement.
  const anim::Clip& walk = *model.find_clip("walk");
  std::vector<anim::JointTransform> local(skeleton.joint_count());
  std::vector<Affine3> model_pose(skeleton.joint_count());
  ASSERT_TRUE(anim::rest_pose(skeleton, local).ok());
  anim::SamplingCache cache;
  anim::sample_clip(walk, anim::clip_time(walk, 0.45, /*loop=*/true), cache, local);
  ASSERT_TRUE(anim::local_to_model(skeleton, local, model_pose).ok());
  const Affine3 expected = to_affine(desc.transform) * model_pose[hand];
  const auto got = world->bone_transform(*id, hand);
  ASSERT_TRUE(got.ok()) << got.error().message;
  EXPECT_LT(max_difference(to_affine(*got), expected), 1e-6f);
  // Hand-checked placement: x' = z + 2, z' = -x - 1.5 of the model-space hand.
  const Vec3 p = model_pose[hand].translation_part();
  EXPECT_NEAR(got->m[0][3], p.z + 2.0f, 1e-5f);
  EXPECT_NEAR(got->m[1][3], p.y, 1e-5f);
  EXPECT_NEAR(got->m[2][3], -p.x - 1.5f, 1e-5f);

  // Host-driven: the bone's world transform is its skinning matrix times
  // its bind pose (bone -> model at bind time).
  api::InstanceDesc host_desc;
  host_desc.driver = api::Driver::kHost;
  const auto host = world->add_instance(character, host_desc);
  ASSERT_TRUE(host.ok());
  std::vector<api::Matrix3x4> skinning(character.bone_count(), api::Matrix3x4::translation(0.5f, 0.0f, 0.25f));
  skinning[hand] = desc.transform;
  ASSERT_TRUE(world->set_bone_matrices(*host, skinning).ok());
  const Affine3 bind = to_affine(character.bind_pose(hand));
  EXPECT_LT(max_difference(to_affine(world->bone_transform(*host, hand).value()), to_affine(desc.transform) * bind),
            1e-5f);
}

TEST(ApiAnimation, BadClockAndBoneArgumentsAreErrorsThatChangeNothing) {
  const api::Character character = load_mannequin();
  auto world = api::World::create();
  ASSERT_TRUE(world.ok());
  const api::InstanceId id = walker(*world, character);
  const std::size_t bones = character.bone_count();
  const std::vector<api::Matrix3x4> before = bones_of(*world, id, bones);
  const float nan = std::nanf("");
  const auto expect_error = [](const api::Status& s, api::ErrorCode code, const std::string& text) {
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, code);
    EXPECT_NE(s.error().message.find(text), std::string::npos) << s.error().message;
  };
  expect_error(world->set_playback_speed(id, -1.0f), api::ErrorCode::kInvalidArgument, "speed");
  expect_error(world->set_playback_speed(id, nan), api::ErrorCode::kInvalidArgument, "speed");
  expect_error(world->offset_time(id, -0.5f), api::ErrorCode::kInvalidArgument, "seconds");
  expect_error(world->offset_time(id, nan), api::ErrorCode::kInvalidArgument, "seconds");
  expect_error(world->set_time_factor(id, nan), api::ErrorCode::kInvalidArgument, "factor");
  expect_error(world->set_playback_speed(99, 1.0f), api::ErrorCode::kNotFound, "instance 99");
  EXPECT_TRUE(same_bits(bones_of(*world, id, bones), before));
  // A speed times a step that overflows moves no instance at all.
  const api::InstanceId other = walker(*world, character);
  const std::vector<api::Matrix3x4> other_before = bones_of(*world, other, bones);
  ASSERT_TRUE(world->set_playback_speed(other, 3.0e38f).ok());
  expect_error(world->advance(10.0f), api::ErrorCode::kInvalidArgument, "playback speed");
  EXPECT_TRUE(same_bits(bones_of(*world, id, bones), before));
  EXPECT_TRUE(same_bits(bones_of(*world, other, bones), other_before));
  ASSERT_TRUE(world->set_playback_speed(other, 1.0f).ok());

  api::InstanceDesc bad;
  bad.playback_speed = -2.0f;
  const auto refused = world->add_instance(character, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("playback_speed"), std::string::npos) << refused.error().message;

  const auto past = world->bone_transform(id, bones);
  ASSERT_FALSE(past.ok());
  EXPECT_EQ(past.error().code, api::ErrorCode::kInvalidArgument);
  EXPECT_NE(past.error().message.find(std::to_string(bones) + " bones"), std::string::npos) << past.error().message;
  const api::Float3 corners[] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  const std::uint32_t tri[] = {0, 1, 2};
  const auto floor = world->add_static_mesh({corners, tri});
  ASSERT_TRUE(floor.ok());
  EXPECT_EQ(world->bone_transform(*floor, 0).error().code, api::ErrorCode::kNotFound);
  // The clock calls are the mixer's: a host-driven instance refuses them.
  api::InstanceDesc host;
  host.driver = api::Driver::kHost;
  const auto hosted = world->add_instance(character, host);
  ASSERT_TRUE(hosted.ok());
  expect_error(world->offset_time(*hosted, 0.1f), api::ErrorCode::kInvalidArgument, "host-driven");
  EXPECT_TRUE(world->bone_transform(*hosted, 0).ok());
}

}  // namespace
}  // namespace sinew
