#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "animation/clip.h"
#include "animation/skeleton.h"
#include "tests/support/joint_chain.h"

namespace sinew::anim {
namespace {

constexpr float kPi = 3.14159265358979f;

Skeleton three_joints() { return *Skeleton::build(testing_support::joint_chain({"root", "a", "b"}), "test"); }

Clip build(RawClip raw) {
  auto c = Clip::build(std::move(raw), three_joints(), "test");
  EXPECT_TRUE(c.ok()) << c.status().message();
  return std::move(c).value();
}

RawClip translation_clip(Interpolation interp, std::vector<float> times, std::vector<Vec3> values) {
  RawClip raw;
  raw.name = "t";
  JointTracks jt;
  jt.joint = 1;
  jt.translation.interpolation = interp;
  jt.translation.times = std::move(times);
  jt.translation.values = std::move(values);
  raw.tracks.push_back(std::move(jt));
  return raw;
}

Vec3 sample_translation(const Clip& clip, float t) {
  SamplingCache cache;
  std::vector<JointTransform> pose(3);
  sample_clip(clip, t, cache, pose);
  return pose[1].translation;
}

TEST(Clip, LinearStepAndHold) {
  const Clip lin = build(translation_clip(Interpolation::kLinear, {1.0f, 3.0f}, {{0, 0, 0}, {4, 2, -2}}));
  EXPECT_FLOAT_EQ(lin.duration(), 3.0f);
  EXPECT_EQ(sample_translation(lin, 2.0f), Vec3(2, 1, -1));
  EXPECT_EQ(sample_translation(lin, 1.5f), Vec3(1, 0.5f, -0.5f));
  // Before the first key: the first value; after the last: the last.
  EXPECT_EQ(sample_translation(lin, 0.0f), Vec3(0, 0, 0));
  EXPECT_EQ(sample_translation(lin, 99.0f), Vec3(4, 2, -2));

  const Clip step = build(translation_clip(Interpolation::kStep, {0.0f, 1.0f, 2.0f},
                                           {{1, 0, 0}, {2, 0, 0}, {3, 0, 0}}));
  EXPECT_EQ(sample_translation(step, 0.99f).x, 1.0f);
  EXPECT_EQ(sample_translation(step, 1.0f).x, 2.0f);
  EXPECT_EQ(sample_translation(step, 1.7f).x, 2.0f);
  EXPECT_EQ(sample_translation(step, 2.5f).x, 3.0f);
}

TEST(Clip, SingleKeyHoldsEverywhere) {
  const Clip c = build(translation_clip(Interpolation::kLinear, {0.5f}, {{7, 8, 9}}));
  for (float t : {0.0f, 0.5f, 10.0f}) EXPECT_EQ(sample_translation(c, t), Vec3(7, 8, 9));
}

// glTF 2.0 spec, Appendix C: p(t) = (2s^3 - 3s^2 + 1) v_k + (s^3 - 2s^2 + s) td b_k
//   + (-2s^3 + 3s^2) v_k+1 + (s^3 - s^2) td a_k+1, with b the out-tangent of k
//   and a the in-tangent of k+1.
TEST(Clip, CubicSplineMatchesTheGltfFormula) {
  const float td = 2.0f;
  const Vec3 v0(1, 0, 0), b0(3, 1, 0), a1(-1, 2, 0), v1(2, 4, 1);
  const Clip c = build(translation_clip(Interpolation::kCubicSpline, {1.0f, 3.0f},
                                        {{9, 9, 9}, v0, b0, a1, v1, {9, 9, 9}}));
  for (float s : {0.0f, 0.25f, 0.5f, 0.8f}) {
    const float s2 = s * s, s3 = s2 * s;
    const Vec3 want = (2 * s3 - 3 * s2 + 1) * v0 + (s3 - 2 * s2 + s) * td * b0 +
                      (-2 * s3 + 3 * s2) * v1 + (s3 - s2) * td * a1;
    const Vec3 got = sample_translation(c, 1.0f + s * td);
    EXPECT_NEAR(got.x, want.x, 1e-5f) << s;
    EXPECT_NEAR(got.y, want.y, 1e-5f) << s;
    EXPECT_NEAR(got.z, want.z, 1e-5f) << s;
  }
  EXPECT_EQ(sample_translation(c, 3.0f), v1);
}

TEST(Clip, SlerpTakesTheShortestPath) {
  const Quat a = glm::angleAxis(0.0f, Vec3(0, 0, 1));
  const Quat b = glm::angleAxis(kPi / 2, Vec3(0, 0, 1));
  const Quat mid = slerp_shortest(a, b, 0.5f);
  EXPECT_NEAR(glm::angle(mid), kPi / 4, 1e-5f);
  // -b is the same rotation; the path must still be the 45 degree one.
  const Quat mid2 = slerp_shortest(a, -b, 0.5f);
  EXPECT_NEAR(std::fabs(glm::dot(mid, mid2)), 1.0f, 1e-6f);
  // Constant angular speed: a third of the way is 30 degrees.
  EXPECT_NEAR(glm::angle(slerp_shortest(a, b, 1.0f / 3.0f)), kPi / 6, 1e-5f);
  // Nearly identical rotations take the nlerp branch and stay unit length.
  const Quat c = glm::angleAxis(1e-4f, Vec3(1, 0, 0));
  EXPECT_NEAR(glm::length(slerp_shortest(a, c, 0.3f)), 1.0f, 1e-6f);
}

TEST(Clip, SequentialAndRandomAccessAgree) {
  std::vector<float> times;
  std::vector<Vec3> values;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  float t = 0.0f;
  for (int k = 0; k < 50; ++k) {
    t += 0.01f + 0.1f * (u(rng) + 1.0f);
    times.push_back(t);
    values.push_back({u(rng), u(rng), u(rng)});
  }
  const Clip c = build(translation_clip(Interpolation::kLinear, times, values));
  SamplingCache cache;
  std::vector<JointTransform> pose(3);
  // Play forward, wrap around, jump back: the cached path must give what a
  // fresh cache (binary search) gives.
  for (int frame = 0; frame < 600; ++frame) {
    const float time = clip_time(c, frame / 30.0, true);
    sample_clip(c, time, cache, pose);
    EXPECT_EQ(pose[1].translation, sample_translation(c, time)) << frame;
  }
}

TEST(Clip, ClipTimeLoopsAndClamps) {
  const Clip c = build(translation_clip(Interpolation::kLinear, {0.0f, 2.0f}, {{0, 0, 0}, {1, 1, 1}}));
  EXPECT_FLOAT_EQ(clip_time(c, 5.0, true), 1.0f);
  EXPECT_FLOAT_EQ(clip_time(c, -0.5, true), 1.5f);
  EXPECT_FLOAT_EQ(clip_time(c, 5.0, false), 5.0f);
  EXPECT_FLOAT_EQ(clip_time(c, -1.0, false), 0.0f);
  const Clip single = build(translation_clip(Interpolation::kLinear, {0.0f}, {{0, 0, 0}}));
  EXPECT_EQ(clip_time(single, 3.3, true), 0.0f);
}

TEST(Clip, UntouchedJointsKeepTheirPose) {
  const Clip c = build(translation_clip(Interpolation::kLinear, {0.0f}, {{1, 1, 1}}));
  SamplingCache cache;
  std::vector<JointTransform> pose(3);
  pose[2].translation = Vec3(5, 5, 5);
  sample_clip(c, 0.0f, cache, pose);
  EXPECT_EQ(pose[2].translation, Vec3(5, 5, 5));
  EXPECT_EQ(pose[0].translation, Vec3(0, 0, 0));
}

// Rotation keys of any finite size are normalised: squares of components
// past about 1.8e19 overflowed float, and such a key was stored as
// (0, 0, 0, 0), which a pack then refused. Unit keys keep their bits.
TEST(Clip, HugeAndTinyRotationKeysAreNormalised) {
  const float big = 3.0e38f;
  const std::pair<Quat, Quat> cases[] = {
      {Quat(1.8e19f, 0, 0, 1.8e19f), Quat(0.70710678f, 0, 0, 0.70710678f)},
      {Quat(big, big, big, big), Quat(0.5f, 0.5f, 0.5f, 0.5f)},
      {Quat(-big, 0, 0, 0), Quat(-1, 0, 0, 0)},
      {Quat(0, 2.0e-6f, 0, 0), Quat(0, 1, 0, 0)},
  };
  // A clip of one rotation key on joint 0, built.
  const auto one_key = [](const Quat& key) {
    RawClip raw;
    raw.name = "r";
    raw.tracks.resize(1);
    raw.tracks[0].rotation.times = {0.0f};
    raw.tracks[0].rotation.values = {key};
    return Clip::build(std::move(raw), three_joints(), "r.caf");
  };
  for (const auto& [key, unit] : cases) {
    auto c = one_key(key);
    ASSERT_TRUE(c.ok()) << c.status().message();
    const Quat q = c->tracks()[0].rotation.values[0];
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(q[i], unit[i], 1e-6f) << i;
      EXPECT_TRUE(std::isfinite(q[i]));
    }
  }
  const Quat unit = glm::normalize(Quat(0.3f, -0.4f, 0.5f, 0.7f));
  auto c = one_key(unit);
  ASSERT_TRUE(c.ok());
  for (int i = 0; i < 4; ++i) EXPECT_EQ(c->tracks()[0].rotation.values[0][i], unit[i]) << "bits kept";
}

// A cubic-spline rotation whose value passes through zero (keys q and -q,
// zero tangents: (0, 0, 0, 0) halfway) was normalised into NaN, and the
// body vanished at that instant with exit 0. Huge finite tangents and keys
// far apart overflow float the same way. Every sample stays finite, and a
// rotation stays unit length, the nearer key standing in where the spline
// has no direction.
TEST(Clip, InterpolationThroughZeroOrOverflowStaysFinite) {
  const float big = 3.0e38f;
  RawClip raw;
  raw.name = "z";
  raw.tracks.resize(2);
  JointTracks& spin = raw.tracks[0];
  spin.joint = 0;
  spin.rotation.interpolation = Interpolation::kCubicSpline;
  spin.rotation.times = {0.0f, 1.0f, 2.0f};
  // (in tangent, value, out tangent) per key.
  spin.rotation.values = {Quat(0, 0, 0, 0), Quat(1, 0, 0, 0),    Quat(0, 0, 0, 0),
                          Quat(0, 0, 0, 0), Quat(-1, 0, 0, 0),   Quat(big, big, 0, 0),
                          Quat(big, 0, big, 0), Quat(0, 0, 1, 0), Quat(0, 0, 0, 0)};
  spin.translation.interpolation = Interpolation::kLinear;
  spin.translation.times = {0.0f, 1.0f};
  spin.translation.values = {Vec3(-big, 0, 0), Vec3(big, 0, 0)};
  JointTracks& move = raw.tracks[1];
  move.joint = 1;
  move.translation.interpolation = Interpolation::kCubicSpline;
  move.translation.times = {0.0f, 1.0f};
  move.translation.values = {Vec3(0), Vec3(1, 0, 0), Vec3(big, big, big), Vec3(big, 0, 0), Vec3(2, 0, 0), Vec3(0)};
  const Clip clip = build(std::move(raw));

  SamplingCache cache;
  std::vector<JointTransform> pose(3);
  sample_clip(clip, 0.5f, cache, pose);  // exactly (0, 0, 0, 0) before normalising
  EXPECT_EQ(pose[0].rotation, Quat(-1, 0, 0, 0)) << "the nearer key (the later one at u = 0.5)";
  for (int i = 0; i <= 200; ++i) {
    const float t = 2.0f * static_cast<float>(i) / 200.0f;
    sample_clip(clip, t, cache, pose);
    for (const JointTransform& j : pose) {
      for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(j.rotation[c])) << "t = " << t;
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(j.translation[c])) << "t = " << t;
      ASSERT_NEAR(glm::length(j.rotation), 1.0f, 1e-5f) << "t = " << t;
    }
  }
}

TEST(Clip, RejectsBadKeysNamingTheField) {
  auto expect_error = [](RawClip raw, ErrorCode code, const char* field) {
    auto c = Clip::build(std::move(raw), three_joints(), "walk.caf");
    ASSERT_FALSE(c.ok());
    EXPECT_EQ(c.status().code(), code);
    EXPECT_THAT(c.status().message(), ::testing::HasSubstr(field));
  };
  expect_error(translation_clip(Interpolation::kLinear, {0.0f, 1.0f, 1.0f}, {{}, {}, {}}),
               ErrorCode::kInvalidData, "translation.times[2]");
  expect_error(translation_clip(Interpolation::kLinear, {0.0f, 2.0f, 1.0f}, {{}, {}, {}}),
               ErrorCode::kInvalidData, "translation.times[2]");
  expect_error(translation_clip(Interpolation::kLinear, {-1.0f}, {{}}), ErrorCode::kInvalidData,
               "times[0]");
  expect_error(translation_clip(Interpolation::kLinear, {0.0f, 1.0f}, {{}}), ErrorCode::kInvalidData,
               "translation.values");
  expect_error(translation_clip(Interpolation::kCubicSpline, {0.0f, 1.0f}, {{}, {}}),
               ErrorCode::kInvalidData, "translation.values");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  expect_error(translation_clip(Interpolation::kLinear, {0.0f}, {{nan, 0, 0}}),
               ErrorCode::kInvalidData, "values[0]");
  RawClip bad_joint = translation_clip(Interpolation::kLinear, {0.0f}, {{}});
  bad_joint.tracks[0].joint = 3;
  expect_error(bad_joint, ErrorCode::kOutOfBounds, "tracks[0].joint");
  RawClip twice = translation_clip(Interpolation::kLinear, {0.0f}, {{}});
  twice.tracks.push_back(twice.tracks[0]);
  expect_error(twice, ErrorCode::kDuplicate, "tracks[1].joint");
  RawClip zero_rot;
  zero_rot.name = "z";
  zero_rot.tracks.resize(1);
  zero_rot.tracks[0].rotation.times = {0.0f};
  zero_rot.tracks[0].rotation.values = {Quat(0, 0, 0, 0)};
  expect_error(zero_rot, ErrorCode::kInvalidData, "rotation.values[0]");
}

}  // namespace
}  // namespace sinew::anim
