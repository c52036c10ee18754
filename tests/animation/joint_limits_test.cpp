#include "animation/joint_limits.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "animation/pose_space.h"
#include "animation/skeleton.h"

namespace sinew::anim {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kDeg = kPi / 180.0f;

constexpr RotationOrder kAllOrders[] = {RotationOrder::kXYZ, RotationOrder::kXZY, RotationOrder::kYXZ,
                                        RotationOrder::kYZX, RotationOrder::kZXY, RotationOrder::kZYX};

// Deterministic random rotations, independent of the code under test's
// sampler (std::mt19937_64 + Shoemake written out here).
class RandomRotations {
 public:
  explicit RandomRotations(std::uint64_t seed) : engine_(seed) {}
  double u() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  Quat next() {
    const double u1 = u(), u2 = u(), u3 = u();
    const double r1 = std::sqrt(1 - u1), r2 = std::sqrt(u1);
    return Quat(static_cast<float>(r2 * std::cos(6.283185307179586 * u3)),
                static_cast<float>(r1 * std::sin(6.283185307179586 * u2)),
                static_cast<float>(r1 * std::cos(6.283185307179586 * u2)),
                static_cast<float>(r2 * std::sin(6.283185307179586 * u3)));
  }

 private:
  std::mt19937_64 engine_;
};

JointLimit euler(RotationOrder order, Vec3 min_deg, Vec3 max_deg) {
  JointLimit l;
  l.kind = LimitKind::kEuler;
  l.euler.order = order;
  l.euler.min = min_deg * kDeg;
  l.euler.max = max_deg * kDeg;
  return l;
}

JointLimit swing_twist(Vec3 axis, float s1_deg, float s2_deg, float t0_deg, float t1_deg) {
  JointLimit l;
  l.kind = LimitKind::kSwingTwist;
  l.swing_twist.twist_axis = glm::normalize(axis);
  l.swing_twist.swing_max_1 = s1_deg * kDeg;
  l.swing_twist.swing_max_2 = s2_deg * kDeg;
  l.swing_twist.twist_min = t0_deg * kDeg;
  l.swing_twist.twist_max = t1_deg * kDeg;
  return l;
}

std::vector<JointLimit> limit_zoo() {
  return {
      euler(RotationOrder::kXYZ, {-90, -30, -45}, {90, 30, 120}),
      euler(RotationOrder::kZYX, {-10, -80, 0}, {10, 80, 0}),  // zero-width z
      euler(RotationOrder::kYZX, {-180, -90, -180}, {180, 90, 180}),
      euler(RotationOrder::kXZY, {0, 0, 0}, {0, 0, 0}),             // pinned
      euler(RotationOrder::kYXZ, {-45, 90, -20}, {45, 90, 20}),     // middle locked at +90
      euler(RotationOrder::kZXY, {-30, -150, -10}, {30, 120, 60}),  // middle wider than 90
      swing_twist({1, 0, 0}, 40, 40, -60, 60),
      swing_twist({0, 1, 0}, 70, 20, -10, 90),
      swing_twist({0.3f, 0.2f, 0.9f}, 0, 50, 0, 0),  // zero-width ellipse and twist
      swing_twist({0, 0, 1}, 180, 180, -180, 180),   // everything
      swing_twist({1, 0, 0}, 30, 10, 170, 180),      // twist range ending at 180
      swing_twist({0, 1, 0}, 0, 0, -180, -170),
  };
}

TEST(JointLimits, EulerRoundTripAllOrdersIncludingGimbalLock) {
  RandomRotations rng(7);
  for (RotationOrder order : kAllOrders) {
    for (int i = 0; i < 2000; ++i) {
      const Quat q = rng.next();
      const EulerAngles e = decompose_euler(order, q);
      EXPECT_LT(rotation_distance(q, compose_euler(order, e.angles)), 2e-5f);
    }
    // Exactly at lock: middle angle +-90 degrees.
    for (float mid : {90.0f, -90.0f}) {
      for (float outer : {-170.0f, -30.0f, 0.0f, 45.0f, 180.0f}) {
        Vec3 a(outer * kDeg, 0.3f, -0.7f);
        // Put `mid` on the middle axis of this order.
        const int middle = order == RotationOrder::kXYZ || order == RotationOrder::kZYX   ? 1
                           : order == RotationOrder::kXZY || order == RotationOrder::kYZX ? 2
                                                                                          : 0;
        a[middle] = mid * kDeg;
        const Quat q = compose_euler(order, a);
        const EulerAngles e = decompose_euler(order, q);
        EXPECT_TRUE(e.gimbal_locked);
        EXPECT_TRUE(std::isfinite(e.angles.x) && std::isfinite(e.angles.y) && std::isfinite(e.angles.z));
        EXPECT_LT(rotation_distance(q, compose_euler(order, e.angles)), 2e-5f);
      }
    }
  }
}

TEST(JointLimits, ClampKeepsRandomRotationsInside) {
  RandomRotations rng(42);
  const auto zoo = limit_zoo();
  int outside = 0;
  for (int i = 0; i < 100000; ++i) {
    const Quat q = rng.next();
    const JointLimit& l = zoo[static_cast<std::size_t>(i) % zoo.size()];
    const Quat c = clamp_rotation(l, q);
    ASSERT_TRUE(std::isfinite(c.w) && std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
    EXPECT_NEAR(glm::length(c), 1.0f, 1e-5f);
    if (!is_within(l, c, 1e-4f)) {
      ++outside;
      if (outside < 5) ADD_FAILURE() << "limit " << i % zoo.size() << " clamp left rotation outside";
    }
    // Idempotent.
    EXPECT_LT(rotation_distance(clamp_rotation(l, c), c), 2e-4f);
  }
  EXPECT_EQ(outside, 0);
}

TEST(JointLimits, AllowedRotationsUnchanged) {
  RandomRotations rng(3);
  const auto zoo = limit_zoo();
  for (int i = 0; i < 20000; ++i) {
    const JointLimit& l = zoo[static_cast<std::size_t>(i) % zoo.size()];
    // Draw an allowed rotation from the limit's own parameters, strictly
    // inside so float rounding cannot push it out.
    Quat q;
    if (l.kind == LimitKind::kEuler) {
      Vec3 a;
      for (int k = 0; k < 3; ++k) {
        const double t = 0.02 + 0.96 * rng.u();
        a[k] = l.euler.min[k] + (l.euler.max[k] - l.euler.min[k]) * static_cast<float>(t);
      }
      q = compose_euler(l.euler.order, a);
    } else {
      const auto& st = l.swing_twist;
      const double r = 0.98 * std::sqrt(rng.u()), psi = 6.283185307179586 * rng.u();
      const Vec2 s(static_cast<float>(r * std::cos(psi)) * st.swing_max_1,
                   static_cast<float>(r * std::sin(psi)) * st.swing_max_2);
      const float t =
          st.twist_min + (st.twist_max - st.twist_min) * static_cast<float>(0.02 + 0.96 * rng.u());
      q = compose_swing_twist(st.twist_axis, s, t);
    }
    if (rng.u() < 0.5) q = -q;  // the other cover is the same rotation
    ASSERT_TRUE(is_within(l, q, 1e-5f)) << "limit " << i % zoo.size();
    const Quat c = clamp_rotation(l, q);
    EXPECT_EQ(c, q) << "limit " << i % zoo.size();
  }
}

TEST(JointLimits, FreeLimitIsIdentityAndGarbageIsSafe) {
  const JointLimit free;
  const Quat q(0.5f, 0.5f, -0.5f, 0.5f);
  EXPECT_EQ(clamp_rotation(free, q), q);
  EXPECT_TRUE(is_within(free, q));
  const float nan = std::nanf("");
  for (const JointLimit& l : limit_zoo()) {
    const Quat c = clamp_rotation(l, Quat(nan, 0, 0, 0));
    EXPECT_TRUE(std::isfinite(c.w) && std::isfinite(c.x));
    EXPECT_TRUE(is_within(l, c, 1e-4f));
    EXPECT_FALSE(is_within(l, Quat(nan, 0, 0, 0)));
    const Quat z = clamp_rotation(l, Quat(0, 0, 0, 0));
    EXPECT_TRUE(std::isfinite(z.w));
  }
}

TEST(JointLimits, EulerClampIsPerAxis) {
  const JointLimit l = euler(RotationOrder::kXYZ, {-10, -20, -30}, {10, 20, 30});
  const Quat q = compose_euler(RotationOrder::kXYZ, Vec3(50, 5, -80) * kDeg);
  const EulerAngles e = decompose_euler(RotationOrder::kXYZ, clamp_rotation(l, q));
  EXPECT_NEAR(e.angles.x, 10 * kDeg, 1e-5f);
  EXPECT_NEAR(e.angles.y, 5 * kDeg, 1e-5f);
  EXPECT_NEAR(e.angles.z, -30 * kDeg, 1e-5f);
}

TEST(JointLimits, EulerGimbalLockPicksAnAllowedSplit) {
  // At y = 90 only x + z is determined: 40 + 0 is outside x's range but
  // 10 + 30 is inside both, so the rotation is allowed and kept.
  const JointLimit l = euler(RotationOrder::kXYZ, {-10, 0, 0}, {10, 90, 60});
  const Quat q = compose_euler(RotationOrder::kXYZ, Vec3(40, 90, 0) * kDeg);
  EXPECT_TRUE(is_within(l, q));
  EXPECT_EQ(clamp_rotation(l, q), q);
  // x + z = 100 > 10 + 60: clamped to the nearest feasible sum, 70.
  const Quat far = compose_euler(RotationOrder::kXYZ, Vec3(100, 90, 0) * kDeg);
  const Quat c = clamp_rotation(l, far);
  EXPECT_TRUE(is_within(l, c, 1e-4f));
  EXPECT_NEAR(rotation_distance(c, far), 30 * kDeg, 1e-4f);
}

TEST(JointLimits, EulerWideMiddleRangeUsesTheSecondDecomposition) {
  // y = 150 decomposes as (x+180, 30, z+180); only the original fits.
  const JointLimit l = euler(RotationOrder::kXYZ, {-20, 100, -20}, {20, 170, 20});
  const Quat q = compose_euler(RotationOrder::kXYZ, Vec3(5, 150, -5) * kDeg);
  EXPECT_TRUE(is_within(l, q));
  EXPECT_EQ(clamp_rotation(l, q), q);
}

TEST(JointLimits, TwistExtremesAt180) {
  const JointLimit l = swing_twist({1, 0, 0}, 0, 0, 170, 180);
  // -179 degrees is 181: 1 degree past the range's 180 end (and 11 short
  // of 170), so it goes to 180.
  const Quat q179 = glm::angleAxis(-179 * kDeg, Vec3(1, 0, 0));
  const Quat c = clamp_rotation(l, q179);
  EXPECT_NEAR(rotation_distance(c, q179), 1 * kDeg, 1e-4f);
  EXPECT_NEAR(rotation_distance(c, glm::angleAxis(kPi, Vec3(1, 0, 0))), 0.0f, 1e-4f);
  // Exactly +-180 is inside, whichever sign the quaternion has.
  const Quat half = glm::angleAxis(kPi, Vec3(1, 0, 0));
  EXPECT_TRUE(is_within(l, half));
  EXPECT_TRUE(is_within(l, -half));
  // A range of exactly [-180, 180] allows any twist.
  const JointLimit all = swing_twist({0, 0, 1}, 0, 0, -180, 180);
  for (float deg : {-180.0f, -179.0f, 0.0f, 179.0f, 180.0f}) {
    EXPECT_TRUE(is_within(all, glm::angleAxis(deg * kDeg, Vec3(0, 0, 1)))) << deg;
  }
  // 175 against [-170, 90]: -170 is 15 degrees away, 90 is 85.
  const JointLimit wrap = swing_twist({0, 0, 1}, 0, 0, -170, 90);
  const Quat w = clamp_rotation(wrap, glm::angleAxis(175 * kDeg, Vec3(0, 0, 1)));
  EXPECT_NEAR(decompose_swing_twist(Vec3(0, 0, 1), w).twist, -170 * kDeg, 1e-4f);
}

// Swings within a degree of a half turn, where the twist of a float
// quaternion is ill-conditioned. The fuzzer found clamp_rotation's result
// rejected by is_within for a 180 x 0 degree ellipse
// (tests/fuzz/corpus/joint_limits/swing-180-clamp.json).
TEST(JointLimits, HalfTurnSwingsClampInsideAndStayPut) {
  RandomRotations rng(19);
  const std::vector<JointLimit> cases = {
      swing_twist({4.6f, 0.8f, 0}, 180, 0, -180, 108),  // the fuzzer's limit
      swing_twist({0, 1, 0}, 180, 90, -30, 30),
      swing_twist({0, 0, 1}, 180, 180, -90, 90),
      swing_twist({1, 1, 1}, 0, 180, 0, 0),
  };
  for (std::size_t li = 0; li < cases.size(); ++li) {
    const JointLimit& l = cases[li];
    const auto& st = l.swing_twist;
    for (int i = 0; i < 4000; ++i) {
      // Any swing direction, angle in [179, 180] degrees, any twist.
      const double psi = 6.283185307179586 * rng.u();
      const double angle = static_cast<double>(kPi) * (1.0 - 0.0056 * rng.u());
      const Vec2 swing(static_cast<float>(angle * std::cos(psi)), static_cast<float>(angle * std::sin(psi)));
      const float twist = kPi * static_cast<float>(2.0 * rng.u() - 1.0);
      const Quat q = compose_swing_twist(st.twist_axis, swing, twist);
      const Quat c = clamp_rotation(l, q);
      ASSERT_NEAR(glm::length(c), 1.0f, 1e-5f) << "limit " << li;
      ASSERT_TRUE(is_within(l, c, 1e-4f)) << "limit " << li << " rotation " << i;
      ASSERT_EQ(clamp_rotation(l, c), c) << "limit " << li << " rotation " << i;
      // The clamp is no farther than the separate projection of swing and
      // twist, an allowed rotation built independently here.
      const Vec2 e(st.swing_max_1 > 0 ? swing.x / st.swing_max_1 : 0.0f,
                   st.swing_max_2 > 0 ? swing.y / st.swing_max_2 : 0.0f);
      const float k = std::max(1.0f, glm::length(e));
      const Vec2 inside(st.swing_max_1 > 0 ? swing.x / k : 0.0f, st.swing_max_2 > 0 ? swing.y / k : 0.0f);
      const float t_inside = std::clamp(twist, st.twist_min, st.twist_max);
      const Quat simple = compose_swing_twist(st.twist_axis, inside, t_inside);
      ASSERT_TRUE(is_within(l, simple, 1e-4f)) << "limit " << li;
      EXPECT_LE(rotation_distance(c, q), rotation_distance(simple, q) + 1e-4f) << "limit " << li;
    }
    // Allowed rotations at the half turn itself come back bit for bit.
    for (int i = 0; i < 1000; ++i) {
      const double a = static_cast<double>(kPi) * (1.0 - 0.0056 * rng.u());
      const Vec2 swing = st.swing_max_1 >= st.swing_max_2 ? Vec2(static_cast<float>(a) * st.swing_max_1 / kPi, 0)
                                                          : Vec2(0, static_cast<float>(a) * st.swing_max_2 / kPi);
      const float t = st.twist_min + (st.twist_max - st.twist_min) * static_cast<float>(rng.u());
      const Quat q = compose_swing_twist(st.twist_axis, rng.u() < 0.5 ? swing : -swing, t);
      ASSERT_TRUE(is_within(l, q, 1e-5f)) << "limit " << li << " allowed " << i;
      ASSERT_EQ(clamp_rotation(l, q), q) << "limit " << li << " allowed " << i;
    }
  }
}

TEST(JointLimits, ZeroWidthRangesPin) {
  RandomRotations rng(11);
  const JointLimit pinned_e = euler(RotationOrder::kYZX, {0, 0, 0}, {0, 0, 0});
  const JointLimit pinned_st = swing_twist({0, 1, 0}, 0, 0, 0, 0);
  for (int i = 0; i < 1000; ++i) {
    const Quat q = rng.next();
    EXPECT_LT(rotation_distance(clamp_rotation(pinned_e, q), Quat(1, 0, 0, 0)), 1e-4f);
    EXPECT_LT(rotation_distance(clamp_rotation(pinned_st, q), Quat(1, 0, 0, 0)), 1e-4f);
  }
}

// Brute force: the clamped rotation is no farther from the input than any
// allowed rotation on a grid over the limit's parameters.
TEST(JointLimits, SwingTwistClampIsNearest) {
  RandomRotations rng(5);
  const std::vector<JointLimit> cases = {
      swing_twist({1, 0, 0}, 40, 40, -60, 60),
      swing_twist({0, 1, 0}, 70, 20, -10, 90),
      swing_twist({0, 0, 1}, 30, 60, 0, 0),
  };
  for (const JointLimit& l : cases) {
    const auto& st = l.swing_twist;
    std::vector<Quat> grid;
    for (int it = 0; it <= 24; ++it) {
      const float t = st.twist_min + (st.twist_max - st.twist_min) * static_cast<float>(it) / 24.0f;
      for (int ir = 0; ir <= 12; ++ir) {
        for (int ia = 0; ia < 48; ++ia) {
          const float r = static_cast<float>(ir) / 12.0f, a = 2 * kPi * static_cast<float>(ia) / 48.0f;
          grid.push_back(compose_swing_twist(
              st.twist_axis, Vec2(r * std::cos(a) * st.swing_max_1, r * std::sin(a) * st.swing_max_2), t));
        }
      }
    }
    double worst_gap = -10.0;
    for (int i = 0; i < 60; ++i) {
      const Quat q = rng.next();
      const float d = rotation_distance(clamp_rotation(l, q), q);
      float best = 10.0f;
      for (const Quat& g : grid) best = std::min(best, rotation_distance(g, q));
      worst_gap = std::max(worst_gap, static_cast<double>(d - best));
    }
    // Negative: the clamp beats every grid point (it searches finer).
    std::printf("swing-twist nearest: worst excess over a %zu-point grid = %.2e rad\n", grid.size(),
                worst_gap);
    EXPECT_LT(worst_gap, 1e-4);
  }
}

// ---- JSON ----------------------------------------------------------------

Skeleton named_skeleton() {
  RawSkeleton raw;
  const char* names[] = {"root", "spine", "neck", "upperarm_l", "upperarm_r"};
  for (int i = 0; i < 5; ++i) {
    RawJoint j;
    j.name = names[i];
    j.parent = i == 0 ? kNoParent : (i < 3 ? i - 1 : 1);
    raw.joints.push_back(j);
  }
  return *Skeleton::build(raw, "test");
}

TEST(JointLimitsJson, ParsesTheDocumentedExample) {
  const Skeleton sk = named_skeleton();
  const auto r =
      parse_joint_limits(R"({"version": 1, "joints": {"upperarm_l": {"type": "euler", "order": "xyz",
      "min_deg": [-90, -30, -45], "max_deg": [90, 30, 120]},
     "neck": {"type": "swing_twist", "twist_axis": [0, 1, 0],
      "swing_deg": [40, 30], "twist_deg": [-60, 60]}}})",
                         sk, "cally.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  const JointLimits& l = *r;
  ASSERT_EQ(l.size(), 5u);
  EXPECT_EQ(l[0].kind, LimitKind::kFree);
  EXPECT_EQ(l[3].kind, LimitKind::kEuler);
  EXPECT_FLOAT_EQ(l[3].euler.max.z, 120 * kDeg);
  EXPECT_EQ(l[2].kind, LimitKind::kSwingTwist);
  EXPECT_FLOAT_EQ(l[2].swing_twist.swing_max_2, 30 * kDeg);
  EXPECT_FLOAT_EQ(l[2].swing_twist.twist_min, -60 * kDeg);
}

TEST(JointLimitsJson, SaveLoadRoundTrip) {
  const Skeleton sk = named_skeleton();
  JointLimits limits(5);
  limits[1] = euler(RotationOrder::kZXY, {-12.5f, -180, 0}, {33.3f, 180, 0});
  limits[2] = swing_twist({0.3f, 0.4f, 0.5f}, 17.25f, 180, -180, 179.9f);
  limits[4] = euler(RotationOrder::kYXZ, {-1e-3f, 90, -90}, {1e-3f, 90, 90});
  const std::string path =
      (std::filesystem::temp_directory_path() / ("sinew_limits_" + std::to_string(::getpid()) + ".json"))
          .string();
  ASSERT_TRUE(save_joint_limits(path, limits, sk).ok());
  const auto back = load_joint_limits(path, sk);
  std::filesystem::remove(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->size(), limits.size());
  for (std::size_t j = 0; j < limits.size(); ++j) {
    const JointLimit& a = limits[j];
    const JointLimit& b = (*back)[j];
    ASSERT_EQ(a.kind, b.kind) << j;
    if (a.kind == LimitKind::kEuler) {
      EXPECT_EQ(a.euler.order, b.euler.order);
      EXPECT_EQ(a.euler.min, b.euler.min) << j;
      EXPECT_EQ(a.euler.max, b.euler.max) << j;
    } else if (a.kind == LimitKind::kSwingTwist) {
      EXPECT_NEAR(glm::length(a.swing_twist.twist_axis - b.swing_twist.twist_axis), 0.0f, 1e-6f);
      EXPECT_EQ(a.swing_twist.swing_max_1, b.swing_twist.swing_max_1);
      EXPECT_EQ(a.swing_twist.swing_max_2, b.swing_twist.swing_max_2);
      EXPECT_EQ(a.swing_twist.twist_min, b.swing_twist.twist_min);
      EXPECT_EQ(a.swing_twist.twist_max, b.swing_twist.twist_max);
    }
  }
  // Hand-friendly degrees: 90 stays 90.
  EXPECT_THAT(joint_limits_to_json(limits, sk), testing::HasSubstr("90.0"));
  EXPECT_THAT(joint_limits_to_json(limits, sk), testing::Not(testing::HasSubstr("89.99")));
}

struct BadCase {
  const char* json;
  const char* field;  // expected Status::field()
};

TEST(JointLimitsJson, ErrorsNameTheField) {
  const Skeleton sk = named_skeleton();
  const BadCase cases[] = {
      {R"([1, 2])", ""},
      {R"({"joints": {}})", "version"},
      {R"({"version": "1"})", "version"},
      {R"({"version": 1, "joints": []})", "joints"},
      {R"({"version": 1, "joints": {"tail": {"type": "free"}}})", "joints.tail"},
      {R"({"version": 1, "joints": {"neck": 3}})", "joints.neck"},
      {R"({"version": 1, "joints": {"neck": {"order": "xyz"}}})", "joints.neck.type"},
      {R"({"version": 1, "joints": {"neck": {"type": 1}}})", "joints.neck.type"},
      {R"({"version": 1, "joints": {"neck": {"type": "hinge"}}})", "joints.neck.type"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xxy", "min_deg": [0,0,0], "max_deg": [0,0,0]}}})",
       "joints.neck.order"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "max_deg": [0,0,0]}}})",
       "joints.neck.min_deg"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,"a",0], "max_deg": [0,0,0]}}})",
       "joints.neck.min_deg[1]"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0], "max_deg": [0,0,0]}}})",
       "joints.neck.min_deg"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,10,0], "max_deg": [0,5,0]}}})",
       "joints.neck.min_deg[1]"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0,0], "max_deg": [0,0,200]}}})",
       "joints.neck.max_deg[2]"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0,0], "max_deg": [0,0,null]}}})",
       "joints.neck.max_deg[2]"},
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0,0], "max_deg": [0,0,1e400]}}})",
       ""},  // not valid JSON for nlohmann: number overflow
      {R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0,0], "max_deg": [0,0,0], "mx": 1}}})",
       "joints.neck.mx"},
      {R"({"version": 1, "joints": {"neck": {"type": "swing_twist", "twist_axis": [0,0,0], "swing_deg": [1,1], "twist_deg": [0,0]}}})",
       "joints.neck.twist_axis"},
      {R"({"version": 1, "joints": {"neck": {"type": "swing_twist", "twist_axis": [0,1,0], "swing_deg": [-1,1], "twist_deg": [0,0]}}})",
       "joints.neck.swing_deg[0]"},
      {R"({"version": 1, "joints": {"neck": {"type": "swing_twist", "twist_axis": [0,1,0], "swing_deg": [1,1], "twist_deg": [10,0]}}})",
       "joints.neck.twist_deg[0]"},
      {R"({"version": 1, "joints": {"neck": {"type": "swing_twist", "twist_axis": [0,1,0], "swing_deg": [1,1]}}})",
       "joints.neck.twist_deg"},
      {R"({"version": 1, "joints": {"neck": {"type": "swing_twist", "twist_axis": [0,1,0], "swing_deg": [1,1], "twist_deg": [NaN,0]}}})",
       ""},                                                          // NaN is not JSON
      {R"({"version": 1, "joints": {"neck": {"type": "free")", ""},  // truncated
  };
  for (const BadCase& c : cases) {
    const auto r = parse_joint_limits(c.json, sk, "limits/cally.json");
    ASSERT_FALSE(r.ok()) << c.json;
    EXPECT_EQ(r.status().file(), "limits/cally.json") << c.json;
    EXPECT_EQ(r.status().field(), c.field) << c.json << " -> " << r.status().message();
  }
  const auto v2 = parse_joint_limits(R"({"version": 2})", sk, "x.json");
  ASSERT_FALSE(v2.ok());
  EXPECT_EQ(v2.status().code(), ErrorCode::kUnsupportedVersion);
  const auto unknown =
      parse_joint_limits(R"({"version": 1, "joints": {"tail": {"type": "free"}}})", sk, "x.json");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(unknown.status().value(), "tail");
  // Missing file.
  EXPECT_EQ(load_joint_limits("/nonexistent/sinew/limits.json", sk).status().code(), ErrorCode::kNotFound);
}

// Every JSON reader bounds nesting before it parses: a limits file nested
// 100,000 levels deep inside a joint is refused by the byte where it passed
// the limit, and one nested as deep as the format needs still loads.
TEST(JointLimitsJson, DeepNestingIsRefusedBeforeParsing) {
  const Skeleton sk = named_skeleton();
  const std::string head = R"({"version": 1, "joints": {"neck": {"type": "free", "x": )";
  const std::string deep = head + std::string(100'000, '[') + std::string(100'000, ']') + "}}}";
  const auto r = parse_joint_limits(deep, sk, "deep.json");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kLimitExceeded) << r.status().message();
  EXPECT_EQ(r.status().file(), "deep.json");
  EXPECT_EQ(r.status().value(), "byte " + std::to_string(head.size() + 13)) << r.status().message();
  EXPECT_LE(r.status().message().size(), 300u);
  const auto shallow = parse_joint_limits(
      R"({"version": 1, "joints": {"neck": {"type": "euler", "order": "xyz", "min_deg": [0,0,0], "max_deg": [0,0,0]}}})",
      sk, "shallow.json");
  EXPECT_TRUE(shallow.ok()) << shallow.status().message();
}

TEST(JointLimits, ValidateAndApply) {
  const Skeleton sk = named_skeleton();
  JointLimits limits(5);
  limits[3] = euler(RotationOrder::kXYZ, {-10, -10, -10}, {10, 10, 10});
  EXPECT_TRUE(validate_joint_limits(limits, "x").ok());
  JointLimits bad = limits;
  bad[3].euler.min.y = 0.5f;
  EXPECT_EQ(validate_joint_limits(bad, "x").field(), "joints[3].euler.min.y");
  bad = limits;
  bad[3].euler.max.x = std::nanf("");
  EXPECT_EQ(validate_joint_limits(bad, "x").field(), "joints[3].euler.max.x");

  std::vector<JointTransform> pose(5);
  pose[3].rotation = glm::angleAxis(1.0f, Vec3(1, 0, 0));
  pose[2].rotation = glm::angleAxis(1.0f, Vec3(0, 1, 0));
  ASSERT_TRUE(apply_joint_limits(sk, limits, pose).ok());
  EXPECT_NEAR(rotation_distance(pose[3].rotation, glm::angleAxis(10 * kDeg, Vec3(1, 0, 0))), 0.0f, 1e-5f);
  EXPECT_EQ(pose[2].rotation, glm::angleAxis(1.0f, Vec3(0, 1, 0)));  // free joint untouched
  EXPECT_EQ(apply_joint_limits(sk, limits, std::span(pose).first(4)).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(apply_joint_limits(sk, std::span(limits).first(2), pose).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace sinew::anim
