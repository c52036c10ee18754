// Mixer and blend-layer tests. Every expected value is computed by hand from
// Cal3D 0.11's rules (see mixer.h and blend.h): linear weight fades, the
// weight-averaged sync period, the action phases, and blendState/lockState.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "animation/blend.h"
#include "animation/clip.h"
#include "animation/mixer.h"
#include "animation/skeleton.h"
#include "tests/support/joint_chain.h"

namespace sinew::anim {
namespace {

constexpr float kEps = 1e-5f;
constexpr float kPi = 3.14159265358979f;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// root -> a -> b, with rest translations that no clip below uses, so a
// joint falling back to its rest pose is recognisable.
Skeleton three_joints() {
  RawSkeleton raw = testing_support::joint_chain({"root", "a", "b"});
  for (std::size_t j = 0; j < 3; ++j) {
    raw.joints[j].rest.translation = Vec3(100.0f + static_cast<float>(j), 0.0f, 0.0f);
  }
  auto s = Skeleton::build(raw, "test");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return std::move(s).value();
}

const Skeleton& skeleton() {
  static const Skeleton s = three_joints();
  return s;
}

Clip build(RawClip raw) {
  auto c = Clip::build(std::move(raw), skeleton(), "test");
  EXPECT_TRUE(c.ok()) << c.status().message();
  return std::move(c).value();
}

Quat about_z(float degrees) { return glm::angleAxis(degrees * kPi / 180.0f, Vec3(0, 0, 1)); }

// A clip of `duration` seconds holding translation `t` and rotation `r` on
// `joint` (two equal keys, so it also fixes the duration).
Clip constant_clip(int joint, float duration, Vec3 t, Quat r = Quat(1, 0, 0, 0)) {
  RawClip raw;
  raw.name = "constant";
  JointTracks jt;
  jt.joint = joint;
  jt.translation.times = {0.0f, duration};
  jt.translation.values = {t, t};
  jt.rotation.times = {0.0f, duration};
  jt.rotation.values = {r, r};
  raw.tracks.push_back(std::move(jt));
  return build(std::move(raw));
}

// translation.x equals the clip time, so the pose shows the phase played.
Clip ramp_clip(int joint, float duration) {
  RawClip raw;
  raw.name = "ramp";
  JointTracks jt;
  jt.joint = joint;
  jt.translation.times = {0.0f, duration};
  jt.translation.values = {Vec3(0.0f), Vec3(duration, 0.0f, 0.0f)};
  raw.tracks.push_back(std::move(jt));
  return build(std::move(raw));
}

struct Evaluated {
  Status status;
  std::vector<JointTransform> pose;
};

Evaluated evaluate(std::span<const Clip> clips, std::span<const BlendLayer> layers) {
  std::vector<SamplingCache> caches(clips.size());
  Evaluated e;
  e.pose.resize(skeleton().joint_count());
  e.status = evaluate_layers(skeleton(), clips, layers, caches, e.pose);
  return e;
}

Evaluated evaluate(std::span<const Clip> clips, const Mixer& mixer) {
  return evaluate(clips, mixer.layers());
}

void expect_vec(const Vec3& got, const Vec3& want) {
  EXPECT_NEAR(got.x, want.x, kEps);
  EXPECT_NEAR(got.y, want.y, kEps);
  EXPECT_NEAR(got.z, want.z, kEps);
}

void expect_quat(const Quat& got, const Quat& want) {
  // q and -q are one rotation.
  const float sign = glm::dot(got, want) < 0.0f ? -1.0f : 1.0f;
  EXPECT_NEAR(got.w, sign * want.w, kEps);
  EXPECT_NEAR(got.x, sign * want.x, kEps);
  EXPECT_NEAR(got.y, sign * want.y, kEps);
  EXPECT_NEAR(got.z, sign * want.z, kEps);
}

void expect_rest(const std::vector<JointTransform>& pose, std::size_t joint) {
  expect_vec(pose[joint].translation, skeleton().rest_pose()[joint].translation);
}

// --- cycles ---------------------------------------------------------------

TEST(Mixer, BlendCycleWeightRampsLinearlyAndReachesTargetAtDelay) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.5f).ok());
  EXPECT_TRUE(m.cycle_active(0));
  EXPECT_EQ(m.cycle_weight(0), 0.0f);  // a new cycle starts at weight 0
  m.update(0.0f);
  EXPECT_NEAR(m.cycle_weight(0), 0.0f, kEps);
  m.update(0.125f);
  EXPECT_NEAR(m.cycle_weight(0), 0.25f, kEps);
  m.update(0.125f);
  EXPECT_NEAR(m.cycle_weight(0), 0.5f, kEps);
  m.update(0.125f);
  EXPECT_NEAR(m.cycle_weight(0), 0.75f, kEps);
  m.update(0.125f);  // delay reached exactly
  EXPECT_EQ(m.cycle_weight(0), 1.0f);
  m.update(1.0f);
  EXPECT_EQ(m.cycle_weight(0), 1.0f);

  // Down to 0.5 over one second: 1 - 0.5 * t.
  ASSERT_TRUE(m.blend_cycle(0, 0.5f, 1.0f).ok());
  m.update(0.25f);
  EXPECT_NEAR(m.cycle_weight(0), 0.875f, kEps);
  m.update(0.5f);
  EXPECT_NEAR(m.cycle_weight(0), 0.625f, kEps);
  m.update(0.5f);  // overshooting the delay lands on the target
  EXPECT_EQ(m.cycle_weight(0), 0.5f);
  EXPECT_EQ(m.cycle_count(), 1u);
}

TEST(Mixer, ZeroWeightOnInactiveCycleDoesNothing) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 0.0f, 1.0f).ok());
  EXPECT_FALSE(m.cycle_active(0));
  EXPECT_TRUE(m.layers().empty());
}

TEST(Mixer, TwoCyclesBlendByNormalisedWeights) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0)),
                                constant_clip(1, 1.0f, Vec3(0, 4, 0), about_z(90.0f))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.blend_cycle(1, 3.0f, 0.0f).ok());
  m.update(0.0f);
  ASSERT_EQ(m.layers().size(), 2u);
  EXPECT_EQ(m.layers()[0].clip, 1);  // newest first, as Cal3D's push_front
  EXPECT_EQ(m.layers()[1].clip, 0);

  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok()) << e.status.message();
  // Clip 1 is copied (weight 3), clip 0 blends in by 1 / (3 + 1):
  // (0,4,0) + 0.25 * ((1,0,0) - (0,4,0)) = (0.25, 3, 0); 90 deg * 0.75.
  expect_vec(e.pose[1].translation, Vec3(0.25f, 3.0f, 0.0f));
  expect_quat(e.pose[1].rotation, about_z(67.5f));
  // Untouched joints take the rest pose.
  expect_rest(e.pose, 0);
  expect_rest(e.pose, 2);
}

TEST(Mixer, SingleLowWeightCycleDrivesItsJointsFully) {
  // Cal3D normalises: a lone cycle at weight 0.2 is not blended with rest.
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 2, 3))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 0.2f, 0.0f).ok());
  m.update(0.0f);
  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  expect_vec(e.pose[1].translation, Vec3(1, 2, 3));
}

TEST(Mixer, SynchronisedCyclesShareTheWeightAveragedPeriod) {
  // walk: 1 s on joint 1; run: 0.5 s on joint 2.
  const std::vector<Clip> clips{ramp_clip(1, 1.0f), ramp_clip(2, 0.5f)};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.blend_cycle(1, 1.0f, 0.0f).ok());
  m.update(0.0f);
  EXPECT_NEAR(m.animation_duration(), 0.75f, kEps);  // (1*1 + 1*0.5) / 2
  EXPECT_EQ(m.animation_time(), 0.0f);
  EXPECT_TRUE(m.cycle_synchronized(0));
  EXPECT_TRUE(m.cycle_synchronized(1));

  m.update(0.3f);
  EXPECT_NEAR(m.animation_time(), 0.3f, kEps);
  EXPECT_NEAR(m.cycle_time(0), 0.4f, kEps);  // 0.3 / 0.75 of 1 s
  EXPECT_NEAR(m.cycle_time(1), 0.2f, kEps);  // 0.3 / 0.75 of 0.5 s

  m.update(0.6f);  // 0.9 wraps to 0.15
  EXPECT_NEAR(m.animation_time(), 0.15f, kEps);
  EXPECT_NEAR(m.cycle_time(0), 0.2f, kEps);
  EXPECT_NEAR(m.cycle_time(1), 0.1f, kEps);
  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  EXPECT_NEAR(e.pose[1].translation.x, 0.2f, kEps);
  EXPECT_NEAR(e.pose[2].translation.x, 0.1f, kEps);

  // Unequal weights: (1*1 + 3*0.5) / 4 = 0.625, effective from the next update.
  ASSERT_TRUE(m.blend_cycle(1, 3.0f, 0.0f).ok());
  m.update(0.0f);
  EXPECT_NEAR(m.animation_duration(), 0.625f, kEps);
}

TEST(Mixer, GlobalTimeAdvancesWithThePreviousPeriod) {
  // Cal3D advances the clock before recomputing the period: on the first
  // update the period is still 0, so the time stays 0.
  const std::vector<Clip> clips{ramp_clip(1, 1.0f)};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  m.update(0.25f);
  EXPECT_EQ(m.animation_time(), 0.0f);
  EXPECT_NEAR(m.animation_duration(), 1.0f, kEps);
  m.update(0.25f);
  EXPECT_NEAR(m.animation_time(), 0.25f, kEps);
}

TEST(Mixer, TimeFactorScalesTheSyncClockOnly) {
  // Cal3D's setTimeFactor: the global clock moves dt * factor; weight fades,
  // actions and async cycles keep real time.
  const std::vector<Clip> clips{ramp_clip(1, 1.0f), ramp_clip(2, 2.0f)};
  Mixer m(clips);
  EXPECT_EQ(m.time_factor(), 1.0f);
  ASSERT_TRUE(m.set_time_factor(2.0f).ok());
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  m.update(0.0f);  // the period becomes 1 s
  m.update(0.2f);
  EXPECT_NEAR(m.animation_time(), 0.4f, kEps);  // 2 x 0.2
  EXPECT_NEAR(m.cycle_time(0), 0.4f, kEps);

  ASSERT_TRUE(m.execute_action(1, 0.4f, 0.0f).ok());
  m.update(0.2f);
  EXPECT_NEAR(m.animation_time(), 0.8f, kEps);
  EXPECT_NEAR(m.action_time(1), 0.2f, kEps);    // real time
  EXPECT_NEAR(m.action_weight(1), 0.5f, kEps);  // 0.2 of the 0.4 s fade-in

  ASSERT_TRUE(m.blend_cycle(0, 0.5f, 0.5f).ok());
  m.update(0.05f);
  EXPECT_NEAR(m.animation_time(), 0.9f, kEps);
  EXPECT_NEAR(m.cycle_weight(0), 0.95f, kEps);  // 1 + (0.5 - 1) x 0.05 / 0.5, real time

  // Negative: the clock runs backwards and wraps into [0, period) as in Cal3D.
  ASSERT_TRUE(m.set_time_factor(-0.5f).ok());
  m.update(0.2f);
  EXPECT_NEAR(m.animation_time(), 0.8f, kEps);  // 0.9 - 0.1
  m.update(2.0f);
  EXPECT_NEAR(m.animation_time(), 0.8f, kEps);  // 0.8 - 1.0 wraps to 0.8
  EXPECT_NEAR(m.cycle_time(0), 0.8f, kEps);

  // An async cycle keeps the rate it had on the clock (1 s of 1 s), not the factor.
  ASSERT_TRUE(m.set_time_factor(3.0f).ok());
  ASSERT_TRUE(m.clear_cycle(0, 10.0f).ok());
  EXPECT_NEAR(m.cycle_time(0), 0.8f, kEps);
  m.update(0.05f);
  EXPECT_NEAR(m.cycle_time(0), 0.85f, kEps);

  const Status bad = m.set_time_factor(kNaN);
  EXPECT_EQ(bad.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(bad.field(), "time_factor");
  EXPECT_EQ(m.time_factor(), 3.0f);
}

TEST(Mixer, ClearCycleDesynchronisesKeepingPhaseAndRate) {
  const std::vector<Clip> clips{ramp_clip(1, 1.0f), ramp_clip(2, 0.5f)};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.blend_cycle(1, 1.0f, 0.0f).ok());
  m.update(0.0f);
  m.update(0.3f);  // global 0.3 of 0.75

  ASSERT_TRUE(m.clear_cycle(1, 1.0f).ok());
  EXPECT_FALSE(m.cycle_synchronized(1));
  // Rate 0.5 / 0.75 = 2/3, so its own time is 0.3 * 2/3 = 0.2: same phase.
  EXPECT_NEAR(m.cycle_time(1), 0.2f, kEps);

  m.update(0.15f);
  EXPECT_NEAR(m.cycle_weight(1), 0.85f, kEps);          // 1 - 0.15 / 1
  EXPECT_NEAR(m.cycle_time(1), 0.3f, kEps);             // 0.2 + 0.15 * 2/3
  EXPECT_NEAR(m.animation_time(), 0.45f, kEps);         // with the old 0.75 period
  EXPECT_NEAR(m.animation_duration(), 1.0f, kEps);      // only walk is in sync now
  EXPECT_NEAR(m.cycle_time(0), 0.45f, kEps);            // 0.45 * 1 / 1
  m.update(0.45f);
  EXPECT_NEAR(m.cycle_time(1), 0.1f, kEps);  // 0.3 + 0.3 = 0.6 wraps to 0.1
  EXPECT_NEAR(m.cycle_weight(1), 0.4f, kEps);  // 0.85 - 0.45
}

TEST(Mixer, ClearCycleFadesToZeroAndRemoves) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.clear_cycle(0, 1.0f).ok());  // inactive: fine, nothing happens
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  m.update(0.0f);
  ASSERT_TRUE(m.clear_cycle(0, 0.5f).ok());
  m.update(0.25f);
  EXPECT_NEAR(m.cycle_weight(0), 0.5f, kEps);
  EXPECT_TRUE(m.cycle_active(0));
  m.update(0.25f);
  EXPECT_FALSE(m.cycle_active(0));
  EXPECT_EQ(m.cycle_count(), 0u);
  EXPECT_TRUE(m.layers().empty());
  EXPECT_EQ(m.animation_duration(), 0.0f);
  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  for (std::size_t j = 0; j < 3; ++j) expect_rest(e.pose, j);
}

TEST(Mixer, ReblendAfterZeroWeightStartsASecondInstance) {
  // Cal3D's blendCycle(id, 0, d) drops the cycle from its table; the next
  // blendCycle(id, w, d) creates a new instance beside the fading one.
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  m.update(0.0f);
  ASSERT_TRUE(m.blend_cycle(0, 0.0f, 1.0f).ok());
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 1.0f).ok());
  EXPECT_EQ(m.cycle_count(), 2u);
  m.update(0.5f);
  ASSERT_EQ(m.layers().size(), 2u);
  EXPECT_NEAR(m.layers()[0].weight, 0.5f, kEps);  // the new one, fading in
  EXPECT_NEAR(m.layers()[1].weight, 0.5f, kEps);  // the old one, fading out
  m.update(0.5f);
  EXPECT_EQ(m.cycle_count(), 1u);
  EXPECT_EQ(m.cycle_weight(0), 1.0f);
}

TEST(Mixer, UnsynchronisedCyclesRunOnTheirOwnClocks) {
  const std::vector<Clip> clips{ramp_clip(1, 1.0f), ramp_clip(2, 0.5f)};
  Mixer m(clips);
  m.set_synchronized_cycles(false);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.blend_cycle(1, 1.0f, 0.0f).ok());
  EXPECT_FALSE(m.cycle_synchronized(0));
  m.update(0.0f);
  m.update(0.375f);
  EXPECT_NEAR(m.cycle_time(0), 0.375f, kEps);
  EXPECT_NEAR(m.cycle_time(1), 0.375f, kEps);
  m.update(0.25f);
  EXPECT_NEAR(m.cycle_time(0), 0.625f, kEps);
  EXPECT_NEAR(m.cycle_time(1), 0.125f, kEps);  // 0.625 mod 0.5
  EXPECT_EQ(m.animation_duration(), 0.0f);
}

TEST(Mixer, TurningSyncOffKeepsThePhase) {
  const std::vector<Clip> clips{ramp_clip(1, 1.0f), ramp_clip(2, 0.5f)};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.blend_cycle(1, 1.0f, 0.0f).ok());
  m.update(0.0f);
  m.update(0.3f);
  m.set_synchronized_cycles(false);
  EXPECT_NEAR(m.cycle_time(0), 0.4f, kEps);
  EXPECT_NEAR(m.cycle_time(1), 0.2f, kEps);
  m.update(0.15f);  // rates 1/0.75 and 0.5/0.75
  EXPECT_NEAR(m.cycle_time(0), 0.6f, kEps);
  EXPECT_NEAR(m.cycle_time(1), 0.3f, kEps);
}

// --- actions --------------------------------------------------------------

TEST(Mixer, ActionFadesInHoldsAndFadesOutBeforeItsEnd) {
  const std::vector<Clip> clips{constant_clip(1, 2.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.execute_action(0, 0.5f, 0.4f, 0.8f).ok());
  EXPECT_TRUE(m.action_active(0));
  EXPECT_EQ(m.action_weight(0), 0.0f);
  m.update(0.25f);
  EXPECT_NEAR(m.action_weight(0), 0.4f, kEps);  // 0.25 / 0.5 * 0.8
  m.update(0.25f);
  EXPECT_NEAR(m.action_weight(0), 0.8f, kEps);  // steady from t = 0.5
  m.update(1.0f);
  EXPECT_NEAR(m.action_weight(0), 0.8f, kEps);  // t = 1.5 < 2 - 0.4
  m.update(0.125f);
  EXPECT_NEAR(m.action_weight(0), 0.75f, kEps);  // (2 - 1.625) / 0.4 * 0.8
  EXPECT_NEAR(m.action_time(0), 1.625f, kEps);
  m.update(0.25f);
  EXPECT_NEAR(m.action_weight(0), 0.25f, kEps);  // (2 - 1.875) / 0.4 * 0.8
  ASSERT_EQ(m.layers().size(), 1u);
  EXPECT_TRUE(m.layers()[0].action);
  EXPECT_NEAR(m.layers()[0].time, 1.875f, kEps);
  m.update(0.125f);  // t = 2: the end
  EXPECT_FALSE(m.action_active(0));
  EXPECT_EQ(m.action_count(), 0u);
  EXPECT_TRUE(m.layers().empty());
}

TEST(Mixer, ActionWithoutFadesStartsSteadyAndEndsAtItsEnd) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.execute_action(0, 0.0f, 0.0f).ok());
  m.update(0.5f);
  EXPECT_EQ(m.action_weight(0), 1.0f);
  m.update(0.5f);
  EXPECT_FALSE(m.action_active(0));
}

TEST(Mixer, LockedActionHoldsTheLastFrameWithItsWeight) {
  const std::vector<Clip> clips{ramp_clip(1, 1.0f)};
  Mixer m(clips);
  ASSERT_TRUE(m.execute_action(0, 0.25f, 0.25f, 0.6f, /*lock=*/true).ok());
  m.update(0.5f);
  EXPECT_NEAR(m.action_weight(0), 0.6f, kEps);
  m.update(0.5f);  // t = 1: not yet past the end
  EXPECT_NEAR(m.action_time(0), 1.0f, kEps);
  m.update(0.5f);  // past the end: stopped, clamped to the end
  EXPECT_EQ(m.action_time(0), 1.0f);
  EXPECT_NEAR(m.action_weight(0), 0.6f, kEps);  // no fade-out when locked
  m.update(10.0f);
  ASSERT_TRUE(m.action_active(0));
  EXPECT_EQ(m.action_time(0), 1.0f);
  EXPECT_NEAR(m.action_weight(0), 0.6f, kEps);

  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  EXPECT_NEAR(e.pose[1].translation.x, 1.0f, kEps);  // last frame, no rest blend

  ASSERT_TRUE(m.remove_action(0).ok());
  EXPECT_FALSE(m.action_active(0));
  const Status again = m.remove_action(0);
  EXPECT_EQ(again.code(), ErrorCode::kNotFound);
}

TEST(Mixer, ActionOverridesCyclesByItsWeight) {
  // clip 0: cycle (0,0,5), identity; clip 1: cycle (0,5,0);
  // clip 2: action (10,0,0), 90 deg about z.
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(0, 0, 5)),
                                constant_clip(1, 1.0f, Vec3(0, 5, 0)),
                                constant_clip(1, 4.0f, Vec3(10, 0, 0), about_z(90.0f))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.execute_action(2, 0.0f, 0.0f, 0.6f).ok());
  m.update(0.5f);
  ASSERT_EQ(m.layers().size(), 2u);
  EXPECT_TRUE(m.layers()[0].action);
  EXPECT_NEAR(m.layers()[0].weight, 0.6f, kEps);

  // Lock after actions: weight 0.6, pose = action. Cycles accumulate 1,
  // clamped to 1 - 0.6 = 0.4, blended in by 0.4 / (0.6 + 0.4) = 0.4:
  // (10,0,0) + 0.4 * ((0,0,5) - (10,0,0)) = (6, 0, 2); 90 deg * 0.6 = 54.
  Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  expect_vec(e.pose[1].translation, Vec3(6, 0, 2));
  expect_quat(e.pose[1].rotation, about_z(54.0f));

  // Two cycles at weight 1 first average to (0, 2.5, 2.5), then get 0.4:
  // (10,0,0) + 0.4 * ((0,2.5,2.5) - (10,0,0)) = (6, 1, 1).
  ASSERT_TRUE(m.blend_cycle(1, 1.0f, 0.0f).ok());
  m.update(0.0f);
  e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  expect_vec(e.pose[1].translation, Vec3(6, 1, 1));
}

TEST(Mixer, ActionsSummingToOneOrMoreHideTheCycles) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(0, 0, 5)),
                                constant_clip(1, 4.0f, Vec3(2, 0, 0)),
                                constant_clip(1, 4.0f, Vec3(0, 2, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  ASSERT_TRUE(m.execute_action(1, 0.0f, 0.0f, 1.0f).ok());
  ASSERT_TRUE(m.execute_action(2, 0.0f, 0.0f, 3.0f).ok());
  m.update(0.5f);
  ASSERT_EQ(m.layers().size(), 3u);
  EXPECT_EQ(m.layers()[0].clip, 2);  // newest action first
  EXPECT_EQ(m.layers()[1].clip, 1);
  // Action 2 copied, action 1 in by 1/4: (0,2,0) + 0.25 * ((2,0,0) - (0,2,0)).
  // The actions' weight 4 clamps to 1, leaving the cycle nothing.
  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  expect_vec(e.pose[1].translation, Vec3(0.5f, 1.5f, 0.0f));
}

TEST(Mixer, ZeroWeightLayersDoNotDisturbTheBlend) {
  // A fresh action (weight 0 until its first update) is copied with weight
  // 0 and then overwritten by the cycle, as in Cal3D.
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(0, 0, 5)),
                                constant_clip(1, 4.0f, Vec3(2, 0, 0))};
  Mixer m(clips);
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 0.0f).ok());
  m.update(0.0f);
  ASSERT_TRUE(m.execute_action(1, 1.0f, 1.0f).ok());
  const Evaluated e = evaluate(clips, m);
  ASSERT_TRUE(e.status.ok());
  expect_vec(e.pose[1].translation, Vec3(0, 0, 5));
}

// --- Cal3D quaternion blend ------------------------------------------------

TEST(Blend, Cal3dQuaternionBlend) {
  expect_quat(cal3d_quat_blend(Quat(1, 0, 0, 0), about_z(90.0f), 0.5f), about_z(45.0f));
  expect_quat(cal3d_quat_blend(Quat(1, 0, 0, 0), about_z(90.0f), 0.0f), Quat(1, 0, 0, 0));
  expect_quat(cal3d_quat_blend(Quat(1, 0, 0, 0), about_z(90.0f), 1.0f), about_z(90.0f));
  // Opposite signs: the shorter arc (q and -q are one rotation).
  expect_quat(cal3d_quat_blend(about_z(10.0f), -about_z(50.0f), 0.5f), about_z(30.0f));
  // Near-parallel: Cal3D's plain lerp, with no renormalisation.
  const Quat q = cal3d_quat_blend(Quat(1, 0, 0, 0), Quat(-1, 0, 0, 0), 0.3f);
  EXPECT_NEAR(q.w, 1.0f, kEps);
}

TEST(Blend, ScaleChannelsBlendLinearly) {
  RawClip raw;
  raw.name = "scale";
  JointTracks jt;
  jt.joint = 2;
  jt.scale.times = {0.0f, 1.0f};
  jt.scale.values = {Vec3(3.0f), Vec3(3.0f)};
  raw.tracks.push_back(jt);
  const std::vector<Clip> clips{build(std::move(raw)),
                                constant_clip(2, 1.0f, Vec3(0, 0, 0))};
  const std::vector<BlendLayer> layers{{0, 0.5f, 1.0f, false}, {1, 0.5f, 1.0f, false}};
  const Evaluated e = evaluate(clips, layers);
  ASSERT_TRUE(e.status.ok());
  // (3,3,3) and the other clip's rest-valued scale (1) at equal weights.
  expect_vec(e.pose[2].scale, Vec3(2.0f));
  // The scale clip leaves translation at rest (102,0,0); the other sets 0.
  expect_vec(e.pose[2].translation, Vec3(51.0f, 0, 0));
}

// --- bad arguments -------------------------------------------------------

TEST(Mixer, BadArgumentsAreInvalidArgumentNamingTheParameter) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0)), Clip()};
  Mixer m(clips);
  auto expect_bad = [](const Status& s, std::string_view field, std::string_view value) {
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument) << s.message();
    EXPECT_EQ(s.field(), field);
    EXPECT_THAT(std::string(s.value()), ::testing::HasSubstr(std::string(value)));
  };
  expect_bad(m.blend_cycle(-1, 1.0f, 0.0f), "clip", "-1");
  expect_bad(m.blend_cycle(2, 1.0f, 0.0f), "clip", "2");
  expect_bad(m.blend_cycle(0, kNaN, 0.0f), "weight", "nan");
  expect_bad(m.blend_cycle(0, -0.5f, 0.0f), "weight", "-0.5");
  expect_bad(m.blend_cycle(0, 1.0f, -1.0f), "delay", "-1");
  expect_bad(m.blend_cycle(0, 1.0f, std::numeric_limits<float>::infinity()), "delay", "inf");
  expect_bad(m.blend_cycle(1, 1.0f, 0.0f), "clip", "1");  // no tracks
  expect_bad(m.clear_cycle(7, 0.0f), "clip", "7");
  expect_bad(m.clear_cycle(0, kNaN), "delay", "nan");
  expect_bad(m.execute_action(-3, 0.0f, 0.0f), "clip", "-3");
  expect_bad(m.execute_action(0, -1.0f, 0.0f), "fade_in", "-1");
  expect_bad(m.execute_action(0, 0.0f, kNaN), "fade_out", "nan");
  expect_bad(m.execute_action(0, 0.0f, 0.0f, -2.0f), "weight", "-2");
  expect_bad(m.remove_action(9), "clip", "9");
  EXPECT_EQ(m.remove_action(0).code(), ErrorCode::kNotFound);
  // Nothing was scheduled by the failed calls.
  EXPECT_EQ(m.cycle_count(), 0u);
  EXPECT_EQ(m.action_count(), 0u);

  // Bad time steps are ignored rather than corrupting the state.
  ASSERT_TRUE(m.blend_cycle(0, 1.0f, 1.0f).ok());
  m.update(kNaN);
  m.update(-1.0f);
  EXPECT_EQ(m.cycle_weight(0), 0.0f);
  m.update(0.5f);
  EXPECT_NEAR(m.cycle_weight(0), 0.5f, kEps);
}

TEST(Blend, BadArgumentsAreRejectedBeforeWriting) {
  const std::vector<Clip> clips{constant_clip(1, 1.0f, Vec3(1, 0, 0))};
  std::vector<SamplingCache> caches(1);
  std::vector<JointTransform> pose(3);
  std::vector<JointTransform> short_pose(2);
  const std::vector<BlendLayer> good{{0, 0.0f, 1.0f, false}};
  EXPECT_EQ(evaluate_layers(skeleton(), clips, good, caches, short_pose).field(),
            "out_local.size()");
  std::vector<SamplingCache> no_caches;
  EXPECT_EQ(evaluate_layers(skeleton(), clips, good, no_caches, pose).field(), "caches.size()");
  const std::vector<BlendLayer> bad_clip{{1, 0.0f, 1.0f, false}};
  EXPECT_EQ(evaluate_layers(skeleton(), clips, bad_clip, caches, pose).field(), "layers[0].clip");
  const std::vector<BlendLayer> bad_weight{{0, 0.0f, 1.0f, false}, {0, 0.0f, kNaN, true}};
  const Status s = evaluate_layers(skeleton(), clips, bad_weight, caches, pose);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(s.field(), "layers[1].weight");
  const std::vector<BlendLayer> bad_time{{0, kNaN, 1.0f, false}};
  EXPECT_EQ(evaluate_layers(skeleton(), clips, bad_time, caches, pose).field(), "layers[0].time");

  // With reusable scratch, repeated evaluation gives the same pose.
  BlendScratch scratch;
  ASSERT_TRUE(evaluate_layers(skeleton(), clips, good, caches, pose, &scratch).ok());
  ASSERT_TRUE(evaluate_layers(skeleton(), clips, good, caches, pose, &scratch).ok());
  expect_vec(pose[1].translation, Vec3(1, 0, 0));
  expect_rest(pose, 0);
}

}  // namespace
}  // namespace sinew::anim
