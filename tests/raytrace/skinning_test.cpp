// Tests for skin_vertices(): both paths against a double-precision reference,
// the paths against each other, thread-count independence, the fused escape
// check on hand-built cases, and the normal options.
//
// Error bound. Each output component is sum_k w_k (sum_j B_kij p_j + t_ki).
// Both paths blend the matrix (at most 8 products summed per entry) and then
// transform (3 products and a translation), so at most 12 rounded operations
// lie on any path from an input to the result: the error is below
// gamma_12 = 12 * 2^-24 ~= 7.2e-7 times S = sum_k |w_k| (sum_j |B_kij p_j| +
// |t_ki|), the sum of the absolute values of the terms (cancellation can make
// the result much smaller than S, which is why the bound scales with S and
// not with the result). We allow kRelTol = 2e-6 (about 3x the worst case);
// a wrong joint, row or weight gives errors of order S. Two paths, each
// within kRelTol * S of the exact value, agree within 2 * kRelTol * S.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <random>
#include <vector>

#include "raytrace/scene/frame_state.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/jobs/job_system.h"

namespace sinew::rt {
namespace {

constexpr double kRelTol = 2e-6;

// Uniform in [0, 1) from the top 24 bits: exact in float, the same everywhere.
float uniform01(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }
float uniform(std::mt19937& rng, float lo, float hi) { return lo + (hi - lo) * uniform01(rng); }
Vec3 uniform_vec3(std::mt19937& rng, float lo, float hi) {
  const float x = uniform(rng, lo, hi);
  const float y = uniform(rng, lo, hi);
  const float z = uniform(rng, lo, hi);
  return {x, y, z};
}

struct MeshShape {
  float position_scale = 1.0f;     // rest positions in [-scale, scale]^3
  float bone_translation = 1.0f;   // bone translations in [-t, t]^3
};

Affine3 random_bone(std::mt19937& rng, float translation) {
  Quat q(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
  q = glm::normalize(q + Quat(0.1f, 0.0f, 0.0f, 0.0f));  // keep away from the zero quaternion
  const Vec3 scale = uniform_vec3(rng, 0.5f, 2.0f);
  return Affine3::from_trs(uniform_vec3(rng, -translation, translation), q, scale);
}

std::vector<Affine3> random_bones(std::mt19937& rng, int count, float translation) {
  std::vector<Affine3> bones;
  for (int b = 0; b < count; ++b) bones.push_back(random_bone(rng, translation));
  return bones;
}

// 1..max_influences influences per vertex in random slots (so live slots are
// not always the first ones), positive weights summing to about 1.
SkinnedMesh random_mesh(std::mt19937& rng, std::size_t vertex_count, int bone_count, MeshShape shape,
                        int max_influences = kMaxInfluences) {
  SkinnedMesh mesh;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    mesh.positions.push_back(uniform_vec3(rng, -shape.position_scale, shape.position_scale));
    const Vec3 n = uniform_vec3(rng, -1.0f, 1.0f) + Vec3(0.0f, 0.0f, 0.01f);
    mesh.normals.push_back(glm::normalize(n));
    std::array<int, kMaxInfluences> slots{0, 1, 2, 3, 4, 5, 6, 7};
    std::shuffle(slots.begin(), slots.end(), rng);
    const int influences = 1 + static_cast<int>(rng() % static_cast<unsigned>(max_influences));
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    float total = 0.0f;
    for (int k = 0; k < influences; ++k) {
      const auto slot = static_cast<std::size_t>(slots[static_cast<std::size_t>(k)]);
      joints[slot] = static_cast<std::uint16_t>(rng() % static_cast<unsigned>(bone_count));
      weights[slot] = uniform(rng, 0.05f, 1.0f);
      total += weights[slot];
    }
    for (float& w : weights) w /= total;
    mesh.joints.push_back(joints);
    mesh.weights.push_back(weights);
  }
  return mesh;
}

struct Reference {
  std::array<double, 3> value{};
  std::array<double, 3> abs_terms{};  // S per component (see the file comment)
};

// sum_k w_k (B_k p [+ t_k]) in double from the same float inputs.
Reference reference_skin(const SkinnedMesh& mesh, std::size_t v, const std::vector<Affine3>& bones,
                         bool is_point) {
  const Vec3& p = is_point ? mesh.positions[v] : mesh.normals[v];
  Reference ref;
  for (std::size_t k = 0; k < kMaxInfluences; ++k) {
    const double w = static_cast<double>(mesh.weights[v][k]);
    if (w == 0.0) continue;
    const Affine3& b = bones[mesh.joints[v][k]];
    for (int r = 0; r < 3; ++r) {
      double sum = 0.0;
      double abs_sum = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double term = static_cast<double>(b(r, c)) * static_cast<double>(p[c]);
        sum += term;
        abs_sum += std::abs(term);
      }
      if (is_point) {
        sum += static_cast<double>(b(r, 3));
        abs_sum += std::abs(static_cast<double>(b(r, 3)));
      }
      ref.value[static_cast<std::size_t>(r)] += w * sum;
      ref.abs_terms[static_cast<std::size_t>(r)] += std::abs(w) * abs_sum;
    }
  }
  return ref;
}

// Largest |got - reference| / S over all vertices and components.
double max_relative_error(const SkinnedMesh& mesh, const std::vector<Affine3>& bones,
                          const std::vector<Vec3>& got, bool is_point) {
  double worst = 0.0;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Reference ref = reference_skin(mesh, v, bones, is_point);
    for (int c = 0; c < 3; ++c) {
      const double err = std::abs(static_cast<double>(got[v][c]) - ref.value[static_cast<std::size_t>(c)]);
      const double scale = ref.abs_terms[static_cast<std::size_t>(c)];
      worst = std::max(worst, scale > 0.0 ? err / scale : (err > 0.0 ? std::numeric_limits<double>::infinity() : 0.0));
    }
  }
  return worst;
}

struct Skinned {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<std::uint8_t> escaped;
  SkinningResult result;
};

Skinned run_skinning(const SkinnedMesh& mesh, const std::vector<Affine3>& bones, SkinningPath path,
                     JobSystem* jobs = nullptr, bool with_normals = true,
                     const EscapeCheckInput* escape = nullptr) {
  Skinned out;
  // Non-zero sentinels so a skipped write is visible.
  out.positions.assign(mesh.vertex_count(), Vec3(-7.0f));
  if (with_normals) out.normals.assign(mesh.vertex_count(), Vec3(-7.0f));
  if (escape != nullptr) out.escaped.assign(escape->vertex_checks.size(), 0xAB);
  SkinningTargets targets{out.positions, out.normals, out.escaped};
  out.result = skin_vertices(mesh, bones, targets, escape, jobs, path);
  return out;
}

std::vector<SkinningPath> available_paths() {
  std::vector<SkinningPath> paths{SkinningPath::kScalar};
  if (avx2_skinning_available()) paths.push_back(SkinningPath::kAvx2);
  return paths;
}

const std::size_t kVertexCounts[] = {0, 1, 7, 8, 9, 1000, 4097};
const MeshShape kShapes[] = {{1.0f, 1.0f}, {1e-3f, 1.0f}, {1e4f, 10.0f}, {1.0f, 1e5f}, {1e-3f, 1e5f}};

TEST(SkinningReference, PositionsAndNormalsMatchDoublePrecision) {
  std::mt19937 rng(1234);
  for (const MeshShape& shape : kShapes) {
    for (const std::size_t count : kVertexCounts) {
      const std::vector<Affine3> bones = random_bones(rng, 23, shape.bone_translation);
      const SkinnedMesh mesh = random_mesh(rng, count, 23, shape);
      for (const SkinningPath path : available_paths()) {
        SCOPED_TRACE(::testing::Message() << "scale " << shape.position_scale << " translation "
                                          << shape.bone_translation << " vertices " << count << " path "
                                          << static_cast<int>(path));
        const Skinned s = run_skinning(mesh, bones, path);
        EXPECT_EQ(s.result.path_used, path);
        EXPECT_EQ(s.result.escaped_checks, 0u);
        EXPECT_LE(max_relative_error(mesh, bones, s.positions, true), kRelTol);
        EXPECT_LE(max_relative_error(mesh, bones, s.normals, false), kRelTol);
      }
    }
  }
}

TEST(SkinningReference, HeaderScalarSkinPointAgrees) {
  std::mt19937 rng(99);
  const std::vector<Affine3> bones = random_bones(rng, 5, 3.0f);
  const SkinnedMesh mesh = random_mesh(rng, 100, 5, {});
  const Skinned s = run_skinning(mesh, bones, SkinningPath::kAuto);
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Reference ref = reference_skin(mesh, v, bones, true);
    const Vec3 p = skin_point(mesh, v, bones);
    for (int c = 0; c < 3; ++c) {
      const double bound = 2.0 * kRelTol * ref.abs_terms[static_cast<std::size_t>(c)];
      EXPECT_NEAR(static_cast<double>(p[c]), static_cast<double>(s.positions[v][c]), bound);
    }
  }
}

TEST(SkinningPaths, ScalarAndAvx2Agree) {
  if (!avx2_skinning_available()) GTEST_SKIP() << "no AVX2+FMA on this CPU";
  std::mt19937 rng(77);
  for (const MeshShape& shape : kShapes) {
    for (const int max_influences : {1, 4, 8}) {
      const std::vector<Affine3> bones = random_bones(rng, 40, shape.bone_translation);
      const SkinnedMesh mesh = random_mesh(rng, 4097, 40, shape, max_influences);
      const Skinned scalar = run_skinning(mesh, bones, SkinningPath::kScalar);
      const Skinned avx2 = run_skinning(mesh, bones, SkinningPath::kAvx2);
      ASSERT_EQ(avx2.result.path_used, SkinningPath::kAvx2);
      for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const Reference rp = reference_skin(mesh, v, bones, true);
        const Reference rn = reference_skin(mesh, v, bones, false);
        for (int c = 0; c < 3; ++c) {
          const auto ci = static_cast<std::size_t>(c);
          ASSERT_NEAR(static_cast<double>(scalar.positions[v][c]), static_cast<double>(avx2.positions[v][c]),
                      2.0 * kRelTol * rp.abs_terms[ci])
              << "vertex " << v;
          ASSERT_NEAR(static_cast<double>(scalar.normals[v][c]), static_cast<double>(avx2.normals[v][c]),
                      2.0 * kRelTol * rn.abs_terms[ci])
              << "vertex " << v;
        }
      }
    }
  }
}

TEST(SkinningPaths, PathUsedReportsWhatRan) {
  std::mt19937 rng(5);
  const std::vector<Affine3> bones = random_bones(rng, 3, 1.0f);
  const SkinnedMesh mesh = random_mesh(rng, 16, 3, {});
  const SkinningPath fast = avx2_skinning_available() ? SkinningPath::kAvx2 : SkinningPath::kScalar;
  EXPECT_EQ(run_skinning(mesh, bones, SkinningPath::kScalar).result.path_used, SkinningPath::kScalar);
  EXPECT_EQ(run_skinning(mesh, bones, SkinningPath::kAvx2).result.path_used, fast);
  EXPECT_EQ(run_skinning(mesh, bones, SkinningPath::kAuto).result.path_used, fast);
}

// Escape checks built around the reference (double) skinned positions: each
// vertex gets 1..3 checks against random bones, with a box that contains the
// bone-frame point with a margin or misses it by a margin, so the expected
// flag does not depend on rounding.
struct RandomChecks {
  std::vector<std::uint32_t> begin;
  std::vector<VertexCheck> checks;
  std::vector<Affine3> bone_from_world;
  std::vector<float> tolerance;
  std::vector<std::uint8_t> expected;
  EscapeCheckInput input() const { return {begin, checks, bone_from_world, tolerance, {}, {}, {}, {}}; }
};

RandomChecks random_checks(std::mt19937& rng, const SkinnedMesh& mesh, const std::vector<Affine3>& bones,
                           unsigned escape_percent = 50) {
  RandomChecks rc;
  for (const Affine3& b : bones) rc.bone_from_world.push_back(inverse(b));
  for (std::size_t b = 0; b < bones.size(); ++b) rc.tolerance.push_back(uniform(rng, 0.0f, 0.05f));
  rc.begin.push_back(0);
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Reference ref = reference_skin(mesh, v, bones, true);
    const Vec3 world(static_cast<float>(ref.value[0]), static_cast<float>(ref.value[1]),
                     static_cast<float>(ref.value[2]));
    const int n = 1 + static_cast<int>(rng() % 3);
    for (int i = 0; i < n; ++i) {
      VertexCheck check;
      check.bone = static_cast<std::uint32_t>(rng() % bones.size());
      const Vec3 q = rc.bone_from_world[check.bone].transform_point(world);
      const Vec3 half = uniform_vec3(rng, 0.1f, 1.0f);
      const bool escapes = rng() % 100 < escape_percent;
      // Shift the box by at least 0.3 beyond its half-size plus the tolerance on one axis.
      Vec3 shift(0.0f);
      if (escapes) shift[static_cast<int>(rng() % 3)] = half.x + half.y + half.z + 0.3f + rc.tolerance[check.bone];
      check.box = Aabb{q - half + shift, q + half + shift};
      rc.checks.push_back(check);
      rc.expected.push_back(escapes ? 1 : 0);
    }
    rc.begin.push_back(static_cast<std::uint32_t>(rc.checks.size()));
  }
  return rc;
}

std::size_t flags_set(const std::vector<std::uint8_t>& flags) {
  return static_cast<std::size_t>(std::count(flags.begin(), flags.end(), std::uint8_t{1}));
}

TEST(SkinningThreads, ResultsIndependentOfThreadCount) {
  std::mt19937 rng(4242);
  const std::vector<Affine3> bones = random_bones(rng, 17, 2.0f);
  const SkinnedMesh mesh = random_mesh(rng, 4097, 17, {2.0f, 2.0f});
  const RandomChecks rc = random_checks(rng, mesh, bones);
  const EscapeCheckInput escape = rc.input();
  JobSystem one(1);
  JobSystem two(2);
  for (const SkinningPath path : available_paths()) {
    SCOPED_TRACE(static_cast<int>(path));
    const Skinned inline_run = run_skinning(mesh, bones, path, nullptr, true, &escape);
    EXPECT_EQ(inline_run.escaped, rc.expected);
    EXPECT_EQ(inline_run.result.escaped_checks, flags_set(rc.expected));
    for (JobSystem* jobs : {&one, &two}) {
      const Skinned threaded = run_skinning(mesh, bones, path, jobs, true, &escape);
      ASSERT_EQ(0, std::memcmp(threaded.positions.data(), inline_run.positions.data(),
                               inline_run.positions.size() * sizeof(Vec3)));
      ASSERT_EQ(0, std::memcmp(threaded.normals.data(), inline_run.normals.data(),
                               inline_run.normals.size() * sizeof(Vec3)));
      EXPECT_EQ(threaded.escaped, inline_run.escaped);
      EXPECT_EQ(threaded.result.escaped_checks, inline_run.result.escaped_checks);
    }
  }
}

// Hand-built: bone 1 translates by (10, 0, 0), bone 2 by (0, 5, 0), bone 3
// has zero scale (its inverse is not finite), bone 4's world-to-bone
// transform scales by 1e38. Every vertex is rigidly bound
// with weight 1, so its bone-frame position in its own bone is its rest
// position (1, 2, 3).
struct HandBuiltScene {
  SkinnedMesh mesh;
  std::vector<Affine3> bones;
  std::vector<std::uint32_t> begin;
  std::vector<VertexCheck> checks;
  std::vector<Affine3> bone_from_world;
  std::vector<float> tolerance{0.0f, 0.05f, 0.05f, 0.05f};
  std::vector<std::uint8_t> expected;

  void add_vertex(std::uint16_t bone, const std::vector<std::pair<VertexCheck, std::uint8_t>>& vertex_checks) {
    mesh.positions.push_back(Vec3(1.0f, 2.0f, 3.0f));
    mesh.normals.push_back(Vec3(0.0f, 0.0f, 1.0f));
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    joints[0] = bone;
    weights[0] = 1.0f;
    mesh.joints.push_back(joints);
    mesh.weights.push_back(weights);
    for (const auto& [check, escaped] : vertex_checks) {
      checks.push_back(check);
      expected.push_back(escaped);
    }
    begin.push_back(static_cast<std::uint32_t>(checks.size()));
  }
};

VertexCheck check_of(std::uint32_t bone, Vec3 lower, Vec3 upper) { return {bone, Aabb{lower, upper}}; }

HandBuiltScene hand_built_scene() {
  HandBuiltScene s;
  s.bones = {Affine3::identity(), Affine3::translation(Vec3(10.0f, 0.0f, 0.0f)),
             Affine3::translation(Vec3(0.0f, 5.0f, 0.0f)),
             Affine3::from_trs(Vec3(1.0f, 1.0f, 1.0f), Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(0.0f))};
  for (const Affine3& b : s.bones) s.bone_from_world.push_back(inverse(b));
  s.bones.push_back(Affine3::identity());  // bone 4, only its bone_from_world matters
  s.bone_from_world.push_back(Affine3::from_trs(Vec3(0.0f), Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(1e38f)));
  s.tolerance.push_back(0.0f);
  s.begin.push_back(0);
  const Vec3 p(1.0f, 2.0f, 3.0f);
  // 0: inside its box.
  s.add_vertex(1, {{check_of(1, p - 0.5f, p + 0.5f), 0}});
  // 1: outside by 0.1 on +x, more than the tolerance 0.05.
  s.add_vertex(1, {{check_of(1, p - 0.5f, p - Vec3(0.1f, -0.5f, -0.5f)), 1}});
  // 2: outside by 0.02 on -y, within the tolerance.
  s.add_vertex(1, {{check_of(1, p + Vec3(-0.5f, 0.02f, -0.5f), p + 0.5f), 0}});
  // 3: no checks at all.
  s.add_vertex(1, {});
  // 4: two checks in different bones; bone 1's box holds it, bone 2's box
  // (the vertex is at p + (10, -5, 0) in bone 2's frame) misses on z.
  s.add_vertex(1, {{check_of(1, p - 0.5f, p + 0.5f), 0},
                   {check_of(2, p + Vec3(10.0f, -5.0f, 0.2f), p + Vec3(10.0f, -5.0f, 0.2f) + 1.0f), 1}});
  // 5: a check against the zero-scale bone fails even with a huge box; the
  // same vertex's check against bone 2 passes.
  s.add_vertex(2, {{check_of(3, Vec3(-1e30f), Vec3(1e30f)), 1}, {check_of(2, p - 0.01f, p + 0.01f), 0}});
  // 6: bound to the zero-scale bone itself: skinned to (1, 1, 1), still fails.
  s.add_vertex(3, {{check_of(3, Vec3(-1e30f), Vec3(1e30f)), 1}});
  // 7: bone 4's frame scales by 1e38, so q overflows to +inf; an unbounded
  // box "contains" it by comparison, but a non-finite q always escapes.
  constexpr float kInf = std::numeric_limits<float>::infinity();
  s.add_vertex(1, {{check_of(4, Vec3(-kInf), Vec3(kInf)), 1}});
  return s;
}

// The hand-built scene's first vertex, moved to `p`.
SkinnedMesh one_vertex_mesh(const HandBuiltScene& s, const Vec3& p) {
  SkinnedMesh mesh;
  mesh.positions = {p};
  mesh.joints = {s.mesh.joints[0]};
  mesh.weights = {s.mesh.weights[0]};
  return mesh;
}

TEST(SkinningEscape, HandBuiltChecks) {
  const HandBuiltScene s = hand_built_scene();
  ASSERT_FALSE(is_finite(s.bone_from_world[3]));  // the premise of the zero-scale cases
  const EscapeCheckInput escape{s.begin, s.checks, s.bone_from_world, s.tolerance, {}, {}, {}, {}};
  JobSystem two(2);
  for (const SkinningPath path : available_paths()) {
    for (JobSystem* jobs : {static_cast<JobSystem*>(nullptr), &two}) {
      const Skinned out = run_skinning(s.mesh, s.bones, path, jobs, false, &escape);
      EXPECT_EQ(out.escaped, s.expected);
      EXPECT_EQ(out.result.escaped_checks, 5u);
      EXPECT_EQ(out.result.escaped_checks, flags_set(out.escaped));
      EXPECT_EQ(out.positions[0], Vec3(11.0f, 2.0f, 3.0f));
      EXPECT_EQ(out.positions[5], Vec3(1.0f, 7.0f, 3.0f));
    }
  }
}

TEST(SkinningEscape, ToleranceIsPerBone) {
  // The same miss of 0.1 passes with bone 2's tolerance 0.2 and fails with bone 1's 0.05.
  HandBuiltScene s = hand_built_scene();
  s.tolerance[2] = 0.2f;
  const Vec3 p(1.0f, 2.0f, 3.0f);
  const Vec3 in_bone2 = p + Vec3(10.0f, -5.0f, 0.0f);
  std::vector<VertexCheck> checks{check_of(1, p + Vec3(0.1f, -0.5f, -0.5f), p + 0.5f),
                                  check_of(2, in_bone2 + Vec3(0.1f, -0.5f, -0.5f), in_bone2 + 0.5f)};
  std::vector<std::uint32_t> begin{0, 2};
  const SkinnedMesh mesh = one_vertex_mesh(s, p);
  const EscapeCheckInput escape{begin, checks, s.bone_from_world, s.tolerance, {}, {}, {}, {}};
  const Skinned out = run_skinning(mesh, s.bones, SkinningPath::kAuto, nullptr, false, &escape);
  EXPECT_EQ(out.escaped, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(out.result.escaped_checks, 1u);
}

TEST(SkinningEscape, BoneWithoutTransformEscapes) {
  // Bone 5 has neither bone_from_world nor tolerance: the safe answer is "escaped".
  const HandBuiltScene s = hand_built_scene();
  const Vec3 p(1.0f, 2.0f, 3.0f);
  std::vector<VertexCheck> checks{check_of(5, Vec3(-1e30f), Vec3(1e30f)), check_of(1, p - 0.5f, p + 0.5f)};
  std::vector<std::uint32_t> begin{0, 2};
  const SkinnedMesh mesh = one_vertex_mesh(s, p);
  const EscapeCheckInput escape{begin, checks, s.bone_from_world, s.tolerance, {}, {}, {}, {}};
  const Skinned out = run_skinning(mesh, s.bones, SkinningPath::kAuto, nullptr, false, &escape);
  EXPECT_EQ(out.escaped, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(out.result.escaped_checks, 1u);
}

// The check's bone-frame point must be Affine3::transform_point's, bit for
// bit (the check runs four lanes at once): boxes whose faces lie exactly on
// that float point hold it, boxes one float beyond it do not (tolerance 0),
// on every axis and side, for random bones and vertices.
TEST(SkinningEscape, BoxFacesOnThePointDecideByItsExactBits) {
  std::mt19937 rng(77);
  const std::vector<Affine3> bones = random_bones(rng, 9, 3.0f);
  const SkinnedMesh mesh = random_mesh(rng, 600, 9, {2.0f, 2.0f});
  for (const SkinningPath path : available_paths()) {
    // Each path's own skinned positions (the paths agree to rounding only).
    const Skinned skinned = run_skinning(mesh, bones, path);
    RandomChecks rc;
    for (const Affine3& b : bones) rc.bone_from_world.push_back(inverse(b));
    rc.tolerance.assign(bones.size(), 0.0f);
    rc.begin.push_back(0);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      const std::uint32_t bone = static_cast<std::uint32_t>(rng() % bones.size());
      const Vec3 q = rc.bone_from_world[bone].transform_point(skinned.positions[v]);
      const int axis = static_cast<int>(rng() % 3);
      const bool upper_face = rng() % 2 == 0;
      const bool beyond = rng() % 2 == 0;
      Aabb box{q - 1.0f, q + 1.0f};
      const float inf = std::numeric_limits<float>::infinity();
      if (upper_face) {
        box.upper[axis] = beyond ? std::nextafter(q[axis], -inf) : q[axis];
      } else {
        box.lower[axis] = beyond ? std::nextafter(q[axis], inf) : q[axis];
      }
      rc.checks.push_back({bone, box});
      rc.expected.push_back(beyond ? 1 : 0);
      rc.begin.push_back(static_cast<std::uint32_t>(rc.checks.size()));
    }
    const EscapeCheckInput escape = rc.input();
    const Skinned out = run_skinning(mesh, bones, path, nullptr, false, &escape);
    ASSERT_EQ(out.positions, skinned.positions);
    EXPECT_EQ(out.escaped, rc.expected);
    EXPECT_GT(flags_set(rc.expected), 200u);
  }
}

// Each chunk's bone boxes, merged in chunk order, are the boxes of every
// bone's checked vertices (what the scene's exact bone boxes are), with any
// thread count.
TEST(SkinningEscape, ChunkBoneBoxesBoundEachBonesCheckedVertices) {
  std::mt19937 rng(91);
  const std::vector<Affine3> bones = random_bones(rng, 13, 2.0f);
  const SkinnedMesh mesh = random_mesh(rng, 4097, 13, {2.0f, 2.0f});
  RandomChecks rc = random_checks(rng, mesh, bones);
  JobSystem two(2);
  for (JobSystem* jobs : {static_cast<JobSystem*>(nullptr), &two}) {
    std::vector<Aabb> chunk_boxes(skinning_chunk_count(mesh.vertex_count()) * bones.size(),
                                  Aabb{Vec3(-7.0f), Vec3(7.0f)});
    EscapeCheckInput escape = rc.input();
    escape.chunk_bone_boxes = chunk_boxes;
    const Skinned out = run_skinning(mesh, bones, SkinningPath::kAuto, jobs, false, &escape);
    std::vector<Aabb> merged(bones.size(), Aabb::empty()), expected(bones.size(), Aabb::empty());
    for (std::size_t row = 0; row < chunk_boxes.size() / bones.size(); ++row) {
      for (std::size_t b = 0; b < bones.size(); ++b) merged[b].extend(chunk_boxes[row * bones.size() + b]);
    }
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      for (std::uint32_t c = rc.begin[v]; c < rc.begin[v + 1]; ++c) expected[rc.checks[c].bone].extend(out.positions[v]);
    }
    for (std::size_t b = 0; b < bones.size(); ++b) {
      EXPECT_EQ(merged[b].lower, expected[b].lower) << "bone " << b;
      EXPECT_EQ(merged[b].upper, expected[b].upper) << "bone " << b;
      EXPECT_FALSE(expected[b].is_empty()) << "bone " << b;
    }
  }
}

// The AVX2 block check (eight vertices with one check each against one
// bone) answers bit for bit as the check by check loop and as the scalar
// expression: vertices in runs of one bone, most with one check, some with
// two or none (so blocks fall back), boxes with a face exactly on the
// bone-frame point or one float beyond it, half the bones held to cluster
// boxes through ranks (shared checks keep their own), and a block whose
// positions are not finite. The chunk bone boxes are the boxes of every
// bone's checked, finite vertices.
TEST(SkinningEscape, BlocksOfOneBoneCheckAsCheckByCheck) {
  std::mt19937 rng(2024);
  constexpr std::size_t kBones = 6;
  const std::vector<Affine3> bones = random_bones(rng, kBones, 3.0f);
  SkinnedMesh mesh = random_mesh(rng, 3 * kSkinningChunkVertices + 21, kBones, {2.0f, 2.0f});
  // Vertices 1608..1615 (a block of eight) skinned to NaN.
  for (std::size_t v = 1608; v < 1616; ++v) mesh.positions[v].y = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (const SkinningPath path : available_paths()) {
    const Skinned skinned = run_skinning(mesh, bones, path);
    RandomChecks rc;
    for (const Affine3& b : bones) rc.bone_from_world.push_back(inverse(b));
    for (std::size_t b = 0; b < kBones; ++b) rc.tolerance.push_back(b % 2 == 0 ? 0.0f : 1e-3f);
    std::vector<std::uint32_t> rank;
    std::vector<std::vector<Aabb>> cluster_boxes(kBones);
    std::vector<Aabb> applied;  // the box each check is held to
    rc.begin.push_back(0);
    std::uint32_t bone = 0;
    std::size_t run_left = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      if (run_left == 0) {
        bone = static_cast<std::uint32_t>(rng() % kBones);
        run_left = 1 + rng() % 40;
      }
      --run_left;
      const unsigned roll = static_cast<unsigned>(rng() % 100);
      const int count = roll < 3 ? 0 : roll < 8 ? 2 : 1;
      for (int i = 0; i < count; ++i) {
        const std::uint32_t b = i == 0 ? bone : static_cast<std::uint32_t>((bone + 1) % kBones);
        const Vec3 q = rc.bone_from_world[b].transform_point(skinned.positions[v]);
        Aabb box{q - 1.0f, q + 1.0f};
        const int axis = static_cast<int>(rng() % 3);
        const bool beyond = rng() % 4 == 0;
        const float tol = rc.tolerance[b];
        // On the face (inside) or one float past the grown face (outside).
        if (rng() % 2 == 0) {
          box.upper[axis] = beyond ? std::nextafter(q[axis] - tol, -inf) - tol : q[axis] - tol;
        } else {
          box.lower[axis] = beyond ? std::nextafter(q[axis] + tol, inf) + tol : q[axis] + tol;
        }
        const Aabb own{box.lower - 5.0f, box.upper + 5.0f};  // holds q: overridden by the cluster box
        const bool clustered_bone = b % 2 == 1;
        const bool boxed = clustered_bone && rng() % 3 != 0;
        rc.checks.push_back({b, boxed ? own : box});
        rank.push_back(boxed ? static_cast<std::uint32_t>(cluster_boxes[b].size()) : kSharedCheckBox);
        if (boxed) cluster_boxes[b].push_back(box);
        applied.push_back(box);
      }
      rc.begin.push_back(static_cast<std::uint32_t>(rc.checks.size()));
    }
    // The expected flags from the scalar expression on each path's own positions.
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      for (std::uint32_t c = rc.begin[v]; c < rc.begin[v + 1]; ++c) {
        const std::uint32_t b = rc.checks[c].bone;
        const Vec3 q = rc.bone_from_world[b].transform_point(skinned.positions[v]);
        const float tol = rc.tolerance[b];
        bool in = std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
        for (int a = 0; a < 3; ++a) in = in && q[a] >= applied[c].lower[a] - tol && q[a] <= applied[c].upper[a] + tol;
        rc.expected.push_back(in ? 0 : 1);
      }
    }
    std::vector<const Aabb*> bone_boxes(kBones, nullptr);
    for (std::size_t b = 1; b < kBones; b += 2) bone_boxes[b] = cluster_boxes[b].data();
    std::vector<Aabb> chunk_boxes(skinning_chunk_count(mesh.vertex_count()) * kBones, Aabb{Vec3(-7.0f), Vec3(7.0f)});
    EscapeCheckInput escape = rc.input();
    escape.chunk_bone_boxes = chunk_boxes;
    escape.bone_boxes = bone_boxes;
    escape.check_rank = rank;
    JobSystem two(2);
    for (JobSystem* jobs : {static_cast<JobSystem*>(nullptr), &two}) {
      const Skinned out = run_skinning(mesh, bones, path, jobs, false, &escape);
      ASSERT_EQ(0, std::memcmp(out.positions.data(), skinned.positions.data(), out.positions.size() * sizeof(Vec3)));
      EXPECT_EQ(out.escaped, rc.expected);
      EXPECT_EQ(out.result.escaped_checks, flags_set(rc.expected));
      EXPECT_GT(flags_set(rc.expected), 400u);
      EXPECT_LT(flags_set(rc.expected), rc.expected.size() / 2);
      // The same flags from check_escapes() on the same positions.
      std::vector<std::uint8_t> again(rc.checks.size(), 0xAB);
      EXPECT_EQ(check_escapes(escape, out.positions, again, jobs), flags_set(rc.expected));
      EXPECT_EQ(again, rc.expected);
      std::vector<Aabb> merged(kBones, Aabb::empty()), expected(kBones, Aabb::empty());
      for (std::size_t row = 0; row < chunk_boxes.size() / kBones; ++row) {
        for (std::size_t b = 0; b < kBones; ++b) merged[b].extend(chunk_boxes[row * kBones + b]);
      }
      for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (v >= 1608 && v < 1616) continue;  // NaN: no box holds them
        for (std::uint32_t c = rc.begin[v]; c < rc.begin[v + 1]; ++c) {
          expected[rc.checks[c].bone].extend(out.positions[v]);
        }
      }
      for (std::size_t b = 0; b < kBones; ++b) {
        EXPECT_EQ(merged[b].lower, expected[b].lower) << "bone " << b;
        EXPECT_EQ(merged[b].upper, expected[b].upper) << "bone " << b;
      }
    }
  }
}

// The tolerance the scene gives a bone (frame_state.cpp, update_bone_frames)
// whose checked rest positions have the box `local`.
float scene_tolerance(const Affine3& to_world, const Aabb& local) {
  const auto max_abs = [](const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); };
  const Affine3 from_world = inverse(to_world);
  float norm = 0.0f;
  for (const Vec4& row : from_world.rows) norm = std::max(norm, std::fabs(row.x) + std::fabs(row.y) + std::fabs(row.z));
  const Aabb world_box = transform(to_world, local);
  const float world = std::max(max_abs(world_box.lower), max_abs(world_box.upper));
  const float local_max = std::max(max_abs(local.lower), max_abs(local.upper));
  return kFrameRelativeSlack * (norm * world + max_abs(from_world.translation_part()) + local_max);
}

// Blocks of rigid checks (rigid_checks.h) answer as their computed checks:
// the same flags, count, positions and chunk bone boxes with and without
// find_rigid_check_blocks' plan, on both paths and with one or two
// threads, from unit scale to far from the origin, with the scene's
// tolerances. Vertices come in runs of one bone, most rigid with a box
// around their rest position (some a point box), the others moved by two
// bones with boxes that hold or miss their bone-frame point. Then three
// bones whose rigid blocks must be computed, and all escape: one skinned
// to infinity (its world -> bone transform kept finite), one of zero scale
// (its inverse is not finite) and one whose tolerance is NaN. (Not bone 0:
// the AVX2 kernel's empty lanes blend it with weight 0, and 0 * inf would
// poison every group with two slots.)
TEST(SkinningEscape, RigidBlocksAnswerAsTheirComputedChecks) {
  std::mt19937 rng(515);
  constexpr std::size_t kBones = 8;
  for (const MeshShape& shape : kShapes) {
    SCOPED_TRACE(shape.position_scale);
    SCOPED_TRACE(shape.bone_translation);
    std::vector<Affine3> bones = random_bones(rng, kBones, shape.bone_translation);
    SkinnedMesh mesh = random_mesh(rng, 2 * kSkinningChunkVertices + 13, kBones, shape, 2);
    std::uint16_t bone = 0;
    bool rigid_run = false;
    std::size_t run_left = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      if (run_left == 0) {
        bone = static_cast<std::uint16_t>(rng() % kBones);
        rigid_run = rng() % 10 < 7;
        run_left = 8 + rng() % 60;
      }
      --run_left;
      mesh.joints[v] = {bone, static_cast<std::uint16_t>((bone + 1) % kBones), 0, 0, 0, 0, 0, 0};
      const bool rigid = rigid_run ? rng() % 40 != 0 : rng() % 3 == 0;
      mesh.weights[v] = rigid ? std::array<float, kMaxInfluences>{1.0f} : std::array<float, kMaxInfluences>{0.5f, 0.5f};
    }
    std::vector<std::uint32_t> begin{0};
    std::vector<VertexCheck> checks;
    std::vector<Aabb> local(kBones, Aabb::empty());
    const Skinned skinned = run_skinning(mesh, bones, SkinningPath::kScalar);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      const std::uint16_t b = mesh.joints[v][0];
      const Vec3& rest = mesh.positions[v];
      local[b].extend(rest);
      Aabb box{rest, rest};
      if (mesh.weights[v][1] != 0.0f) {
        const Vec3 q = inverse(bones[b]).transform_point(skinned.positions[v]);
        const float half = 0.01f * shape.position_scale;
        box = rng() % 2 == 0 ? Aabb{q - half, q + half} : Aabb{q + 3.0f * half, q + 5.0f * half};
      } else if (rng() % 2 == 0) {
        box = Aabb{rest - uniform_vec3(rng, 0.0f, 0.1f), rest + uniform_vec3(rng, 0.0f, 0.1f)};
      }
      checks.push_back({b, box});
      begin.push_back(static_cast<std::uint32_t>(checks.size()));
    }
    const std::vector<std::uint16_t> rigid = find_rigid_check_blocks(mesh, pack_influences(mesh), begin, checks, {});
    const auto rigid_count = static_cast<std::size_t>(std::count_if(rigid.begin(), rigid.end(), [](std::uint16_t r) {
      return r != kNotRigid;
    }));
    ASSERT_GT(rigid_count, rigid.size() / 4);
    // The three bones that must not skip: 3 skinned to infinity, 1 of zero
    // scale, 2 with a NaN tolerance.
    std::vector<Affine3> bone_from_world;
    std::vector<float> tolerance;
    for (std::size_t b = 0; b < kBones; ++b) {
      bone_from_world.push_back(inverse(bones[b]));
      tolerance.push_back(scene_tolerance(bones[b], local[b]));
    }
    const Affine3 finite_bone3 = bones[3];
    bones[3].rows[0].w = std::numeric_limits<float>::infinity();
    bone_from_world[3] = inverse(finite_bone3);
    bones[1] = Affine3::from_trs(Vec3(1.0f), Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(0.0f));
    bone_from_world[1] = inverse(bones[1]);
    ASSERT_FALSE(is_finite(bone_from_world[1]));
    tolerance[2] = std::numeric_limits<float>::quiet_NaN();
    const EscapeCheckInput computed{begin, checks, bone_from_world, tolerance, {}, {}, {}, {}};
    EscapeCheckInput planned = computed;
    planned.rigid_blocks = rigid;
    JobSystem two(2);
    for (const SkinningPath path : available_paths()) {
      for (JobSystem* jobs : {static_cast<JobSystem*>(nullptr), &two}) {
        std::vector<Aabb> computed_boxes(skinning_chunk_count(mesh.vertex_count()) * kBones, Aabb{Vec3(-7.0f), Vec3(7.0f)});
        std::vector<Aabb> planned_boxes = computed_boxes;
        EscapeCheckInput with_boxes = computed;
        with_boxes.chunk_bone_boxes = computed_boxes;
        const Skinned want = run_skinning(mesh, bones, path, jobs, true, &with_boxes);
        with_boxes = planned;
        with_boxes.chunk_bone_boxes = planned_boxes;
        const Skinned got = run_skinning(mesh, bones, path, jobs, true, &with_boxes);
        ASSERT_EQ(0, std::memcmp(got.positions.data(), want.positions.data(), got.positions.size() * sizeof(Vec3)));
        EXPECT_EQ(got.escaped, want.escaped);
        EXPECT_EQ(got.result.escaped_checks, want.result.escaped_checks);
        for (std::size_t i = 0; i < planned_boxes.size(); ++i) {
          ASSERT_EQ(planned_boxes[i].lower, computed_boxes[i].lower) << "box " << i;
          ASSERT_EQ(planned_boxes[i].upper, computed_boxes[i].upper) << "box " << i;
        }
        std::vector<std::uint8_t> again(checks.size(), 0xAB);
        EXPECT_EQ(check_escapes(planned, got.positions, again, jobs), want.result.escaped_checks);
        EXPECT_EQ(again, want.escaped);
        // Every check of bones 1, 2 and 3 escapes; of the others, only the
        // moved vertices' boxes set to miss.
        std::size_t rigid_escapes = 0;
        for (std::size_t c = 0; c < checks.size(); ++c) {
          if (checks[c].bone >= 1 && checks[c].bone <= 3) {
            ASSERT_EQ(got.escaped[c], 1) << "check " << c;
          } else if (mesh.weights[c][1] == 0.0f) {
            rigid_escapes += got.escaped[c];
          }
        }
        EXPECT_EQ(rigid_escapes, 0u);
        EXPECT_GT(got.result.escaped_checks, 0u);
      }
    }
  }
}

// A group of eight vertices rigid on one bone takes the AVX2 kernel's
// broadcast short cut (skinning_avx2.cpp, blend_bones); the same vertices in
// a group that has a second bone take the general blend. Both give the same
// bits, signed zeros included (a bone with -0 translation and rows that
// make -0 products skins the origin to +0 either way). The scalar path,
// which blends vertex by vertex, must agree with itself the same way.
TEST(SkinningPaths, RigidGroupsSkinAsMixedGroups) {
  std::mt19937 rng(3);
  std::vector<Affine3> bones = random_bones(rng, 3, 5.0f);
  bones[2] = Affine3::from_trs(Vec3(-0.0f), Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(-1.0f));
  for (const std::uint16_t bone : {std::uint16_t{0}, std::uint16_t{2}}) {
    SkinnedMesh mesh;
    for (std::size_t group = 0; group < 2; ++group) {
      for (std::size_t lane = 0; lane < 8; ++lane) {
        mesh.positions.push_back(lane == 0 ? Vec3(0.0f) : uniform_vec3(rng, -2.0f, 2.0f));
        mesh.normals.push_back(lane == 0 ? Vec3(0.0f) : glm::normalize(uniform_vec3(rng, 0.1f, 1.0f)));
        const bool other = group == 1 && lane == 7;
        mesh.joints.push_back({static_cast<std::uint16_t>(other ? 1 : bone)});
        mesh.weights.push_back({1.0f});
      }
    }
    // The second group repeats the first's positions but for its last lane.
    for (std::size_t lane = 0; lane < 7; ++lane) {
      mesh.positions[8 + lane] = mesh.positions[lane];
      mesh.normals[8 + lane] = mesh.normals[lane];
    }
    for (const SkinningPath path : available_paths()) {
      const Skinned out = run_skinning(mesh, bones, path);
      ASSERT_EQ(out.result.path_used, path);
      for (std::size_t lane = 0; lane < 7; ++lane) {
        ASSERT_EQ(0, std::memcmp(&out.positions[lane], &out.positions[8 + lane], sizeof(Vec3))) << "lane " << lane;
        ASSERT_EQ(0, std::memcmp(&out.normals[lane], &out.normals[8 + lane], sizeof(Vec3))) << "lane " << lane;
      }
      if (bone == 2) {
        EXPECT_FALSE(std::signbit(out.positions[0].x));
        EXPECT_FALSE(std::signbit(out.positions[8].x));
      }
    }
  }
}

TEST(SkinningNormals, SkippedWhenTargetIsEmpty) {
  std::mt19937 rng(8);
  const std::vector<Affine3> bones = random_bones(rng, 6, 3.0f);
  const SkinnedMesh mesh = random_mesh(rng, 1000, 6, {});
  for (const SkinningPath path : available_paths()) {
    const Skinned s = run_skinning(mesh, bones, path, nullptr, false);
    EXPECT_TRUE(s.normals.empty());
    EXPECT_LE(max_relative_error(mesh, bones, s.positions, true), kRelTol);
  }
}

TEST(SkinningNormals, BlendedWithoutRenormalising) {
  // Scaled bones make the blended normal's length differ from 1; it must stay so.
  std::mt19937 rng(9);
  std::vector<Affine3> bones = random_bones(rng, 6, 3.0f);
  const SkinnedMesh mesh = random_mesh(rng, 1000, 6, {});
  for (const SkinningPath path : available_paths()) {
    const Skinned s = run_skinning(mesh, bones, path, nullptr, true);
    EXPECT_LE(max_relative_error(mesh, bones, s.normals, false), kRelTol);
    const auto not_unit = std::count_if(s.normals.begin(), s.normals.end(),
                                        [](const Vec3& n) { return std::abs(glm::length(n) - 1.0f) > 0.01f; });
    EXPECT_GT(not_unit, 100);
  }
}

TEST(SkinningNormals, SkippedWhenMeshHasNone) {
  std::mt19937 rng(10);
  const std::vector<Affine3> bones = random_bones(rng, 4, 1.0f);
  SkinnedMesh mesh = random_mesh(rng, 40, 4, {});
  mesh.normals.clear();
  for (const SkinningPath path : available_paths()) {
    const Skinned s = run_skinning(mesh, bones, path, nullptr, true);
    for (const Vec3& n : s.normals) EXPECT_EQ(n, Vec3(-7.0f));  // untouched sentinels
    EXPECT_LE(max_relative_error(mesh, bones, s.positions, true), kRelTol);
  }
}

TEST(SkinningEdge, ShortTargetIsNotOverrun) {
  // The header makes sizes the caller's duty; the kernel still stays in bounds.
  std::mt19937 rng(11);
  const std::vector<Affine3> bones = random_bones(rng, 4, 1.0f);
  const SkinnedMesh mesh = random_mesh(rng, 20, 4, {});
  std::vector<Vec3> positions(13, Vec3(-7.0f));
  const SkinningResult r = skin_vertices(mesh, bones, {positions, {}, {}}, nullptr, nullptr);
  EXPECT_EQ(r.escaped_checks, 0u);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const Reference ref = reference_skin(mesh, v, bones, true);
    EXPECT_NEAR(static_cast<double>(positions[v].x), ref.value[0], kRelTol * ref.abs_terms[0]);
  }
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// Not a test: prints ms per frame. Run with
//   sinew_raytrace_tests --gtest_also_run_disabled_tests --gtest_filter='SkinningBenchmark*'
TEST(SkinningBenchmark, DISABLED_MsPerFrame) {
  std::mt19937 rng(2024);
  const std::size_t vertices = 100000;
  const std::vector<Affine3> bones = random_bones(rng, 60, 2.0f);
  SkinnedMesh mesh = random_mesh(rng, vertices, 60, {1.0f, 2.0f}, 4);
  // Exactly 4 influences in slots 0..3, as an exporter writes them.
  for (std::size_t v = 0; v < vertices; ++v) {
    std::array<std::uint16_t, kMaxInfluences> j{};
    std::array<float, kMaxInfluences> w{};
    for (std::size_t k = 0; k < 4; ++k) {
      j[k] = static_cast<std::uint16_t>(rng() % 60);
      w[k] = 0.25f;
    }
    mesh.joints[v] = j;
    mesh.weights[v] = w;
  }
  const RandomChecks rc = random_checks(rng, mesh, bones, 1);  // a pose inside the pose space: few escapes
  const EscapeCheckInput escape = rc.input();
  std::vector<Vec3> positions(vertices);
  std::vector<Vec3> normals(vertices);
  std::vector<std::uint8_t> escaped(rc.checks.size());
  JobSystem one(1);
  JobSystem two(2);
  std::printf("%zu vertices, 4 influences, normals, %.2f checks per vertex\n", vertices,
              static_cast<double>(rc.checks.size()) / static_cast<double>(vertices));
  for (const SkinningPath path : available_paths()) {
    for (JobSystem* jobs : {&one, &two}) {
      for (const bool with_escape : {false, true}) {
        std::vector<double> ms;
        std::vector<double> cpu_ms;  // this thread's CPU time: robust on a loaded machine for 1 thread
        for (int run = 0; run < 21; ++run) {
          const double cpu0 = thread_cpu_ms();
          const auto t0 = std::chrono::steady_clock::now();
          skin_vertices(mesh, bones, {positions, normals, escaped}, with_escape ? &escape : nullptr, jobs, path);
          ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
          cpu_ms.push_back(thread_cpu_ms() - cpu0);
        }
        std::sort(ms.begin(), ms.end());
        std::sort(cpu_ms.begin(), cpu_ms.end());
        std::printf("  %-6s threads %d escape %-3s: wall median %.3f ms (min %.3f), calling-thread cpu median %.3f ms\n",
                    path == SkinningPath::kAvx2 ? "avx2" : "scalar", jobs->thread_count(), with_escape ? "yes" : "no",
                    ms[ms.size() / 2], ms.front(), cpu_ms[cpu_ms.size() / 2]);
      }
    }
  }
}

}  // namespace
}  // namespace sinew::rt
