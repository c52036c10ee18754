// Tests of the fuzzy bake (raytrace/bake/fuzzy_bake.h) against independent
// references: every sampled vertex is re-skinned and re-transformed in double
// precision, and each triangle's bone choice is re-derived by brute force
// over its candidate bones.
//
// Float slack: the bake skins and inverts in float, the references in double.
// Positions here are O(1..20), so the difference is a few float ulps of the
// magnitudes involved; kSlack (relative to max(1, |value|)) is ~100x that.
#include "raytrace/bake/fuzzy_bake.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "raytrace/fuzzy/pose_clusters.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/brute_force.h"

namespace sinew::rt {
namespace {

constexpr double kSlack = 1e-5;

// Deterministic floats in [lo, hi) from mt19937's raw 32-bit output.
class Rng {
 public:
  explicit Rng(std::uint32_t seed) : gen_(seed) {}
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(gen_() >> 8) / 16777216.0;
  }
  glm::dvec3 unit_vector() {
    for (;;) {
      const glm::dvec3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      const double len = glm::length(v);
      if (len > 0.1 && len <= 1.0) return v / len;
    }
  }

 private:
  std::mt19937 gen_;
};

// ---------------------------------------------------------------------------
// Rigs: a mesh, its skeleton and pose samples.

struct Rig {
  SkinnedMesh mesh;
  std::vector<int> parents;
  std::vector<Affine3> samples;  // sample-major
  std::uint32_t bone_count() const { return static_cast<std::uint32_t>(parents.size()); }
  std::size_t sample_count() const { return samples.size() / parents.size(); }
  std::span<const Affine3> pose(std::size_t s) const {
    return std::span<const Affine3>(samples).subspan(s * parents.size(), parents.size());
  }
  FuzzyBakeInput input() const { return {&mesh, bone_count(), parents, samples}; }
};

Affine3 to_affine(const glm::dmat4& m) { return Affine3::from_mat4(Mat4(m)); }

glm::dmat4 rotation_about(const glm::dvec3& pivot, const glm::dvec3& axis, double angle) {
  const glm::dmat4 id(1.0);
  return glm::translate(id, pivot) * glm::rotate(id, angle, axis) * glm::translate(id, -pivot);
}

// A cylinder along +x of `bones` unit-long bones in a chain (bone b spans
// x in [b, b+1], its joint at x = b), with weights blended over +-0.3 around
// each joint and rigid elsewhere.
SkinnedMesh arm_mesh(int bones, int segments, double ring_step) {
  SkinnedMesh mesh;
  const int rings = static_cast<int>(std::lround(bones / ring_step)) + 1;
  for (int r = 0; r < rings; ++r) {
    const double x = r * ring_step;
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    const int nearest_joint = static_cast<int>(std::lround(x));
    const double blend = (x - (nearest_joint - 0.3)) / 0.6;
    if (nearest_joint >= 1 && nearest_joint < bones && blend > 0.0 && blend < 1.0) {
      joints[0] = static_cast<std::uint16_t>(nearest_joint - 1);
      joints[1] = static_cast<std::uint16_t>(nearest_joint);
      weights[0] = static_cast<float>(1.0 - blend);
      weights[1] = 1.0f - weights[0];
    } else {
      joints[0] = static_cast<std::uint16_t>(std::clamp(static_cast<int>(std::floor(x)), 0, bones - 1));
      weights[0] = 1.0f;
    }
    for (int s = 0; s < segments; ++s) {
      const double a = 2.0 * 3.14159265358979 * s / segments;
      mesh.positions.emplace_back(static_cast<float>(x), static_cast<float>(0.3 * std::cos(a)),
                                  static_cast<float>(0.3 * std::sin(a)));
      mesh.joints.push_back(joints);
      mesh.weights.push_back(weights);
    }
  }
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const auto at = [&](int ring, int seg) {
        return static_cast<std::uint32_t>(ring * segments + (seg % segments));
      };
      mesh.triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      mesh.triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
  return mesh;
}

std::vector<int> chain_parents(int bones) {
  std::vector<int> parents(static_cast<std::size_t>(bones));
  for (int b = 0; b < bones; ++b) parents[static_cast<std::size_t>(b)] = b - 1;
  return parents;
}

// Random poses of a chain whose bone b pivots at (b, 0, 0); the first sample
// is the bind pose when `with_bind_pose`.
std::vector<Affine3> chain_poses(const std::vector<int>& parents, int sample_count, double max_angle,
                                 std::uint32_t seed, bool with_bind_pose) {
  Rng rng(seed);
  std::vector<Affine3> samples;
  for (int s = 0; s < sample_count; ++s) {
    std::vector<glm::dmat4> global(parents.size());
    for (std::size_t b = 0; b < parents.size(); ++b) {
      glm::dmat4 local(1.0);
      if (!(with_bind_pose && s == 0)) {
        local = rotation_about(glm::dvec3(static_cast<double>(b), 0, 0), rng.unit_vector(),
                               rng.uniform(-max_angle, max_angle));
        if (parents[b] < 0) {
          local = glm::translate(glm::dmat4(1.0), glm::dvec3(rng.uniform(-2, 2), rng.uniform(-2, 2),
                                                             rng.uniform(-2, 2))) *
                  local;
        }
      }
      global[b] = parents[b] < 0 ? local : global[static_cast<std::size_t>(parents[b])] * local;
      samples.push_back(to_affine(global[b]));
    }
  }
  return samples;
}

Rig arm_rig(int bones, int sample_count, std::uint32_t seed, bool with_bind_pose = false) {
  Rig rig;
  rig.mesh = arm_mesh(bones, 8, 0.25);
  rig.parents = chain_parents(bones);
  rig.samples = chain_poses(rig.parents, sample_count, 1.0, seed, with_bind_pose);
  return rig;
}

// ---------------------------------------------------------------------------
// Double-precision reference

struct RefAffine {
  glm::dmat3 r;
  glm::dvec3 t;
};

RefAffine to_ref(const Affine3& m) {
  RefAffine a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a.r[j][i] = static_cast<double>(m(i, j));
    a.t[i] = static_cast<double>(m(i, 3));
  }
  return a;
}

RefAffine invert(const RefAffine& a) {
  RefAffine b;
  b.r = glm::inverse(a.r);
  b.t = -(b.r * a.t);
  return b;
}

glm::dvec3 apply(const RefAffine& a, const glm::dvec3& p) { return a.r * p + a.t; }

glm::dvec3 skin_ref(const SkinnedMesh& mesh, std::size_t v, std::span<const Affine3> pose) {
  const glm::dvec3 p(mesh.positions[v]);
  glm::dvec3 out(0.0);
  for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
    const double w = static_cast<double>(mesh.weights[v][k]);
    if (w != 0.0) out += w * apply(to_ref(pose[mesh.joints[v][k]]), p);
  }
  return out;
}

struct RefBox {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  void extend(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  double area() const {
    const glm::dvec3 e = hi - lo;
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

double slack_for(double magnitude) { return kSlack * std::max(1.0, std::fabs(magnitude)); }

bool box_contains(const Aabb& box, const glm::dvec3& p) {
  for (int i = 0; i < 3; ++i) {
    if (p[i] < static_cast<double>(box.lower[i]) - slack_for(p[i])) return false;
    if (p[i] > static_cast<double>(box.upper[i]) + slack_for(p[i])) return false;
  }
  return true;
}

// Per sample: every skinned vertex (double) and every bone's inverse (double).
struct RefSamples {
  std::vector<std::vector<glm::dvec3>> skinned;     // [s][v]
  std::vector<std::vector<RefAffine>> bone_from_pose;  // [s][b]
};

RefSamples reference_samples(const Rig& rig) {
  RefSamples ref;
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    std::vector<glm::dvec3> skinned;
    for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) skinned.push_back(skin_ref(rig.mesh, v, rig.pose(s)));
    std::vector<RefAffine> inverses;
    for (const Affine3& m : rig.pose(s)) inverses.push_back(invert(to_ref(m)));
    ref.skinned.push_back(std::move(skinned));
    ref.bone_from_pose.push_back(std::move(inverses));
  }
  return ref;
}

RefBox reference_triangle_box(const Rig& rig, const RefSamples& ref, std::size_t t, std::uint32_t bone) {
  RefBox box;
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    for (std::uint32_t v : rig.mesh.triangles[t]) box.extend(apply(ref.bone_from_pose[s][bone], ref.skinned[s][v]));
  }
  return box;
}

// kInfluencing's rule, derived independently: influencing bones, their
// parents and their children.
std::set<std::uint32_t> influencing_set(const Rig& rig, std::size_t t) {
  std::set<std::uint32_t> out;
  for (std::uint32_t v : rig.mesh.triangles[t]) {
    for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
      if (rig.mesh.weights[v][k] == 0.0f) continue;
      const std::uint32_t b = rig.mesh.joints[v][k];
      out.insert(b);
      if (rig.parents[b] >= 0) out.insert(static_cast<std::uint32_t>(rig.parents[b]));
      for (std::uint32_t c = 0; c < rig.bone_count(); ++c) {
        if (rig.parents[c] == static_cast<int>(b)) out.insert(c);
      }
    }
  }
  return out;
}

std::set<std::uint32_t> candidate_set(const Rig& rig, std::size_t t, CandidateBones mode) {
  if (mode == CandidateBones::kInfluencing) return influencing_set(rig, t);
  std::set<std::uint32_t> all;
  for (std::uint32_t b = 0; b < rig.bone_count(); ++b) all.insert(b);
  return all;
}

FuzzyCharacterData bake_ok(const Rig& rig, const FuzzyBakeOptions& options = {}, int threads = 2) {
  JobSystem jobs(threads);
  Expected<FuzzyCharacterData> result = bake_fuzzy_character(rig.input(), options, jobs);
  if (!result.ok()) {
    ADD_FAILURE() << result.status().message();
    return {};
  }
  return std::move(result).value();
}

// The candidate search alone: rigid bones are not merged (the rigs below
// tie bones together on purpose).
FuzzyBakeOptions with_candidates(CandidateBones mode) {
  FuzzyBakeOptions options;
  options.candidates = mode;
  options.merge_rigid_bones = false;
  return options;
}

Aabb triangle_box(const FuzzyCharacterData& data, std::size_t t) {
  Aabb box;
  for (std::uint32_t c : data.triangle_checks[t]) box.extend(data.vertex_checks[c].box);
  return box;
}

// ---------------------------------------------------------------------------

class FuzzyBakeModes : public ::testing::TestWithParam<CandidateBones> {};

INSTANTIATE_TEST_SUITE_P(FuzzyBake, FuzzyBakeModes,
                         ::testing::Values(CandidateBones::kAll, CandidateBones::kInfluencing),
                         [](const ::testing::TestParamInfo<CandidateBones>& param_info) {
                           return param_info.param == CandidateBones::kAll ? std::string("All")
                                                                     : std::string("Influencing");
                         });

TEST_P(FuzzyBakeModes, EverySampledVertexLiesInsideEachOfItsChecks) {
  const Rig rig = arm_rig(4, 24, 11);
  const FuzzyCharacterData data = bake_ok(rig, with_candidates(GetParam()));
  const RefSamples ref = reference_samples(rig);
  ASSERT_EQ(data.vertex_check_begin.size(), rig.mesh.vertex_count() + 1);
  std::size_t checked = 0;
  for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
    for (std::uint32_t c = data.vertex_check_begin[v]; c < data.vertex_check_begin[v + 1]; ++c) {
      const VertexCheck& check = data.vertex_checks[c];
      for (std::size_t s = 0; s < rig.sample_count(); ++s) {
        const glm::dvec3 local = apply(ref.bone_from_pose[s][check.bone], ref.skinned[s][v]);
        ASSERT_TRUE(box_contains(check.box, local))
            << "vertex " << v << " bone " << check.bone << " sample " << s;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, rig.mesh.vertex_count() * rig.sample_count());
}

TEST_P(FuzzyBakeModes, ChecksAreOnePerDistinctTriangleBoneOfEachVertex) {
  const Rig rig = arm_rig(4, 12, 12);
  const FuzzyCharacterData data = bake_ok(rig, with_candidates(GetParam()));
  std::vector<std::set<std::uint32_t>> expected(rig.mesh.vertex_count());
  for (std::size_t t = 0; t < rig.mesh.triangle_count(); ++t) {
    for (std::uint32_t v : rig.mesh.triangles[t]) expected[v].insert(data.triangle_bone[t]);
  }
  for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
    std::vector<std::uint32_t> bones;
    for (std::uint32_t c = data.vertex_check_begin[v]; c < data.vertex_check_begin[v + 1]; ++c) {
      bones.push_back(data.vertex_checks[c].bone);
    }
    EXPECT_EQ(bones, std::vector<std::uint32_t>(expected[v].begin(), expected[v].end())) << "vertex " << v;
  }
  ASSERT_EQ(data.triangle_checks.size(), rig.mesh.triangle_count());
  for (std::size_t t = 0; t < rig.mesh.triangle_count(); ++t) {
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t v = rig.mesh.triangles[t][i];
      const std::uint32_t c = data.triangle_checks[t][i];
      EXPECT_GE(c, data.vertex_check_begin[v]);
      EXPECT_LT(c, data.vertex_check_begin[v + 1]);
      EXPECT_EQ(data.vertex_checks[c].bone, data.triangle_bone[t]);
    }
  }
}

TEST_P(FuzzyBakeModes, EachTriangleGetsTheCandidateWithTheSmallestBox) {
  const CandidateBones mode = GetParam();
  const Rig rig = arm_rig(4, 16, 13);
  const FuzzyCharacterData data = bake_ok(rig, with_candidates(mode));
  const RefSamples ref = reference_samples(rig);
  ASSERT_EQ(data.triangle_bone.size(), rig.mesh.triangle_count());
  std::size_t restricted = 0;
  for (std::size_t t = 0; t < rig.mesh.triangle_count(); ++t) {
    const std::set<std::uint32_t> candidates = candidate_set(rig, t, mode);
    if (candidates.size() < rig.bone_count()) ++restricted;
    const std::uint32_t chosen = data.triangle_bone[t];
    ASSERT_TRUE(candidates.count(chosen)) << "triangle " << t << " got non-candidate bone " << chosen;
    const RefBox chosen_box = reference_triangle_box(rig, ref, t, chosen);
    const double tolerance = kSlack * (1.0 + chosen_box.area());
    for (std::uint32_t b : candidates) {
      const double area = reference_triangle_box(rig, ref, t, b).area();
      EXPECT_GE(area, chosen_box.area() - tolerance) << "triangle " << t << ": bone " << b << " is smaller";
    }
    // The baked triangle box is the reference box of its bone, up to rounding.
    const Aabb baked = triangle_box(data, t);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(static_cast<double>(baked.lower[i]), chosen_box.lo[i], slack_for(chosen_box.lo[i]));
      EXPECT_NEAR(static_cast<double>(baked.upper[i]), chosen_box.hi[i], slack_for(chosen_box.hi[i]));
    }
  }
  // kInfluencing must actually narrow the search on a 4-bone chain.
  EXPECT_EQ(restricted > 0, mode == CandidateBones::kInfluencing);
}

TEST_P(FuzzyBakeModes, ExactTiesGoToTheLowestCandidate) {
  // Every bone moves identically in every sample, so every candidate's box
  // is bit-identical: the choice must be the lowest candidate.
  Rig rig = arm_rig(4, 8, 14);
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    for (std::size_t b = 1; b < rig.bone_count(); ++b) rig.samples[s * rig.bone_count() + b] = rig.samples[s * rig.bone_count()];
  }
  const FuzzyCharacterData data = bake_ok(rig, with_candidates(GetParam()));
  for (std::size_t t = 0; t < rig.mesh.triangle_count(); ++t) {
    EXPECT_EQ(data.triangle_bone[t], *candidate_set(rig, t, GetParam()).begin()) << "triangle " << t;
  }
}

// A hand-made skeleton: 0 <- 1 <- 2 <- 3, and 4 a second child of 1. One
// triangle weighted to bone 2 only, so kInfluencing's candidates are
// {1, 2, 3}. Bone b's matrix is bone 2's composed with a uniform scale k_b,
// so the triangle's box in b is its rest box scaled by 1 / k_b: the area
// ranks the bones by k_b.
Rig scaled_family_rig(const std::array<double, 5>& scale) {
  Rig rig;
  rig.parents = {-1, 0, 1, 2, 1};
  const std::array<Vec3, 3> corners{Vec3(1.0f, 0.2f, 0.1f), Vec3(1.5f, -0.3f, 0.4f), Vec3(1.2f, 0.5f, -0.6f)};
  for (const Vec3& p : corners) {
    rig.mesh.positions.push_back(p);
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    joints[0] = 2;
    weights[0] = 1.0f;
    rig.mesh.joints.push_back(joints);
    rig.mesh.weights.push_back(weights);
  }
  rig.mesh.triangles.push_back({0, 1, 2});
  Rng rng(21);
  for (int s = 0; s < 6; ++s) {
    const glm::dmat4 bone2 = glm::translate(glm::dmat4(1.0), glm::dvec3(rng.uniform(-1, 1), 0, 0)) *
                             glm::rotate(glm::dmat4(1.0), rng.uniform(-3, 3), rng.unit_vector());
    for (double k : scale) rig.samples.push_back(to_affine(bone2 * glm::scale(glm::dmat4(1.0), glm::dvec3(k))));
  }
  return rig;
}

TEST(FuzzyBakeCandidates, InfluencingSearchesTheBoneItsParentAndItsChildrenOnly) {
  // Bones 0 and 4 (grandparent, sibling) would give the smallest box.
  {
    const Rig rig = scaled_family_rig({4.0, 1.5, 1.0, 2.0, 4.0});
    EXPECT_EQ(bake_ok(rig, with_candidates(CandidateBones::kAll)).triangle_bone[0], 0);
    EXPECT_EQ(bake_ok(rig, with_candidates(CandidateBones::kInfluencing)).triangle_bone[0], 3);  // the child
  }
  {
    const Rig rig = scaled_family_rig({4.0, 3.0, 1.0, 2.0, 4.0});
    EXPECT_EQ(bake_ok(rig, with_candidates(CandidateBones::kInfluencing)).triangle_bone[0], 1);  // the parent
  }
  {
    const Rig rig = scaled_family_rig({0.5, 0.5, 1.0, 0.5, 4.0});
    EXPECT_EQ(bake_ok(rig, with_candidates(CandidateBones::kAll)).triangle_bone[0], 4);
    EXPECT_EQ(bake_ok(rig, with_candidates(CandidateBones::kInfluencing)).triangle_bone[0], 2);  // itself
  }
}

// A chain whose bones in `still` keep one fixed turn about their pivot
// relative to their parent in every sample (plus `wobble` radians of
// random turn, when given); the others move at random as in arm_rig.
Rig arm_rig_with_still_bones(int bones, int sample_count, std::uint32_t seed, const std::set<int>& still,
                             double wobble = 0.0) {
  Rig rig;
  rig.mesh = arm_mesh(bones, 8, 0.25);
  rig.parents = chain_parents(bones);
  Rng rng(seed);
  for (int s = 0; s < sample_count; ++s) {
    std::vector<glm::dmat4> global(rig.parents.size());
    for (std::size_t b = 0; b < rig.parents.size(); ++b) {
      const glm::dvec3 pivot(static_cast<double>(b), 0, 0);
      glm::dmat4 local;
      if (still.count(static_cast<int>(b))) {
        local = rotation_about(pivot, glm::normalize(glm::dvec3(0.3, 1.0, 0.2)), 0.4 + 0.1 * static_cast<double>(b));
        if (wobble > 0.0) local = rotation_about(pivot, rng.unit_vector(), rng.uniform(-wobble, wobble)) * local;
      } else {
        local = rotation_about(pivot, rng.unit_vector(), rng.uniform(-1.0, 1.0));
      }
      global[b] = rig.parents[b] < 0 ? local : global[static_cast<std::size_t>(rig.parents[b])] * local;
      rig.samples.push_back(to_affine(global[b]));
    }
  }
  return rig;
}

std::set<std::uint32_t> bones_with_triangles(const FuzzyCharacterData& data) {
  return std::set<std::uint32_t>(data.triangle_bone.begin(), data.triangle_bone.end());
}

TEST_P(FuzzyBakeModes, BonesRigidWithTheirParentGiveTheirTrianglesToTheMovingAncestor) {
  // 0 <- 1 <- 2 <- 3 <- 4 <- 5: bones 2 and 3 never move relative to their
  // parents, so both stand for bone 1; 4 and 5 move again.
  const Rig rig = arm_rig_with_still_bones(6, 20, 31, {2, 3});
  FuzzyBakeOptions options = with_candidates(GetParam());
  options.merge_rigid_bones = true;
  const FuzzyCharacterData merged = bake_ok(rig, options);
  EXPECT_TRUE(merged.stats.merge_rigid_bones);
  EXPECT_EQ(merged.stats.merged_bones, 2u);
  const std::set<std::uint32_t> used = bones_with_triangles(merged);
  EXPECT_EQ(used.count(2) + used.count(3), 0u);
  EXPECT_TRUE(used.count(1)) << "bone 1 takes the still bones' triangles";
  EXPECT_EQ(merged.bone_trees[2].triangle_count + merged.bone_trees[3].triangle_count, 0u);
  // Still conservative: every sampled vertex inside its checks.
  const RefSamples ref = reference_samples(rig);
  for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
    for (std::uint32_t c = merged.vertex_check_begin[v]; c < merged.vertex_check_begin[v + 1]; ++c) {
      const VertexCheck& check = merged.vertex_checks[c];
      for (std::size_t s = 0; s < rig.sample_count(); ++s) {
        ASSERT_TRUE(box_contains(check.box, apply(ref.bone_from_pose[s][check.bone], ref.skinned[s][v])))
            << "vertex " << v << " bone " << check.bone << " sample " << s;
      }
    }
  }
  // Without merging the still bones keep triangles of their own.
  const FuzzyCharacterData kept = bake_ok(rig, with_candidates(GetParam()));
  EXPECT_FALSE(kept.stats.merge_rigid_bones);
  EXPECT_EQ(kept.stats.merged_bones, 0u);
  const std::set<std::uint32_t> kept_used = bones_with_triangles(kept);
  EXPECT_GT(kept_used.count(2) + kept_used.count(3), 0u);
}

TEST(FuzzyBakeMerge, ABoneThatMovesALittleIsNotMerged) {
  // A hundredth of a radian of play is far above the tolerance (1e-4 of the
  // bind diagonal), so bone 2 stays a bone of its own.
  const Rig rig = arm_rig_with_still_bones(4, 20, 32, {2}, 0.01);
  EXPECT_EQ(bake_ok(rig).stats.merged_bones, 0u);
  const Rig still = arm_rig_with_still_bones(4, 20, 32, {2});
  EXPECT_EQ(bake_ok(still).stats.merged_bones, 1u);
}

TEST(FuzzyBakeMerge, OneSampleMergesEveryBoneIntoTheRoot) {
  // A static model (the rest pose alone): nothing moves relative to
  // anything, so one tree holds every triangle.
  const Rig rig = arm_rig(5, 1, 33);
  const FuzzyCharacterData data = bake_ok(rig);
  EXPECT_EQ(data.stats.merged_bones, 4u);
  EXPECT_EQ(bones_with_triangles(data), std::set<std::uint32_t>{0});
  EXPECT_EQ(data.bone_trees[0].triangle_count, rig.mesh.triangle_count());
}

TEST(FuzzyBakeRigid, RigidVerticesHavePointBoxesAtTheirRestPosition) {
  const Rig rig = arm_rig(4, 16, 15, /*with_bind_pose=*/true);
  const FuzzyCharacterData data = bake_ok(rig);
  std::size_t rigid_checks = 0;
  for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
    if (rig.mesh.weights[v][0] != 1.0f) continue;
    for (std::uint32_t c = data.vertex_check_begin[v]; c < data.vertex_check_begin[v + 1]; ++c) {
      const VertexCheck& check = data.vertex_checks[c];
      if (check.bone != rig.mesh.joints[v][0]) continue;
      ++rigid_checks;
      for (int i = 0; i < 3; ++i) {
        const double rest = static_cast<double>(rig.mesh.positions[v][i]);
        EXPECT_NEAR(static_cast<double>(check.box.lower[i]), rest, slack_for(rest)) << "vertex " << v;
        EXPECT_NEAR(static_cast<double>(check.box.upper[i]), rest, slack_for(rest)) << "vertex " << v;
      }
    }
  }
  EXPECT_GT(rigid_checks, rig.mesh.vertex_count() / 4);

  // With the bind pose among the samples, every fuzzy box contains its rest
  // triangle (every frame is model space there), so the fuzzy area bounds the
  // rest area from above; rigid triangles kept on their bone have exactly
  // their rest box.
  std::size_t rigid_triangles = 0;
  for (std::size_t t = 0; t < rig.mesh.triangle_count(); ++t) {
    const Aabb fuzzy = triangle_box(data, t);
    Aabb rest;
    bool rigid_on_bone = true;
    for (std::uint32_t v : rig.mesh.triangles[t]) {
      rest.extend(rig.mesh.positions[v]);
      EXPECT_TRUE(box_contains(fuzzy, glm::dvec3(rig.mesh.positions[v])));
      rigid_on_bone = rigid_on_bone && rig.mesh.weights[v][0] == 1.0f && rig.mesh.joints[v][0] == data.triangle_bone[t];
    }
    if (!rigid_on_bone) continue;
    ++rigid_triangles;
    EXPECT_NEAR(static_cast<double>(fuzzy.surface_area()), static_cast<double>(rest.surface_area()), 1e-4);
  }
  EXPECT_GT(rigid_triangles, 0u);
  EXPECT_GE(data.stats.fuzzy_area, data.stats.rest_area * (1.0 - kSlack));
  EXPECT_GT(data.stats.fuzzy_area, data.stats.rest_area);  // the joints do bend
}

// ---------------------------------------------------------------------------
// Determinism

template <typename T>
void expect_same_bytes(const std::vector<T>& a, const std::vector<T>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(0, a.empty() ? 0 : std::memcmp(a.data(), b.data(), a.size() * sizeof(T))) << what;
}

void expect_identical(const FuzzyCharacterData& a, const FuzzyCharacterData& b) {
  EXPECT_EQ(a.bone_count, b.bone_count);
  expect_same_bytes(a.triangle_bone, b.triangle_bone, "triangle_bone");
  expect_same_bytes(a.bone_trees, b.bone_trees, "bone_trees");
  expect_same_bytes(a.nodes, b.nodes, "nodes");
  expect_same_bytes(a.bvh_nodes, b.bvh_nodes, "bvh_nodes");
  EXPECT_EQ(a.tree_kind, b.tree_kind);
  expect_same_bytes(a.items, b.items, "items");
  expect_same_bytes(a.vertex_check_begin, b.vertex_check_begin, "vertex_check_begin");
  expect_same_bytes(a.vertex_checks, b.vertex_checks, "vertex_checks");
  expect_same_bytes(a.triangle_checks, b.triangle_checks, "triangle_checks");
  expect_same_bytes(a.bone_cluster_begin, b.bone_cluster_begin, "bone_cluster_begin");
  expect_same_bytes(a.clusters, b.clusters, "clusters");
  expect_same_bytes(a.check_rank, b.check_rank, "check_rank");
  expect_same_bytes(a.cluster_boxes, b.cluster_boxes, "cluster_boxes");
  expect_same_bytes(a.feature_bones, b.feature_bones, "feature_bones");
  expect_same_bytes(a.cluster_centres, b.cluster_centres, "cluster_centres");
  EXPECT_EQ(a.stats.fuzzy_area, b.stats.fuzzy_area);
  EXPECT_EQ(a.stats.node_count, b.stats.node_count);
}

TEST_P(FuzzyBakeModes, ChunkingAndThreadCountDoNotChangeTheResult) {
  const Rig rig = arm_rig(5, 20, 16);
  FuzzyBakeOptions options = with_candidates(GetParam());
  const FuzzyCharacterData reference = bake_ok(rig, options, 2);

  FuzzyBakeOptions one_bone = options;
  one_bone.memory_budget_bytes = 1;  // forces one bone per chunk
  const FuzzyCharacterData chunked = bake_ok(rig, one_bone, 2);
  expect_identical(reference, chunked);
  EXPECT_GE(reference.stats.peak_bytes, rig.mesh.vertex_count() * rig.bone_count() * sizeof(Aabb));
  EXPECT_LE(chunked.stats.peak_bytes, reference.stats.peak_bytes);

  FuzzyBakeOptions two_bones = options;
  two_bones.memory_budget_bytes = rig.mesh.vertex_count() * sizeof(Aabb) * 2;  // 3 uneven chunks
  expect_identical(reference, bake_ok(rig, two_bones, 2));

  expect_identical(reference, bake_ok(rig, options, 1));
  expect_identical(reference, bake_ok(rig, one_bone, 3));
}

// From kFineMeshTriangles triangles on, the bone trees build with
// kFineMeshIntersectionCost unless fine_mesh_cost is cleared: the same
// bytes as an explicit kd.intersection_cost of 0.05 there, and of the
// given cost below it or with the default off.
TEST(FuzzyBakeTrees, FineMeshesBuildWithTheFineMeshCost) {
  Rig fine = arm_rig(4, 6, 3);
  fine.mesh = arm_mesh(4, 200, 0.125);  // 33 rings x 200 segments: 12,800 triangles
  Rig finer = fine;
  finer.mesh = arm_mesh(4, 400, 0.125);  // 25,600 triangles
  ASSERT_LT(fine.mesh.triangle_count(), kFineMeshTriangles);
  ASSERT_GE(finer.mesh.triangle_count(), kFineMeshTriangles);

  FuzzyBakeOptions kd_trees;
  kd_trees.bone_trees = BoneTreeKind::kKdTree;
  FuzzyBakeOptions fixed = kd_trees;
  fixed.fine_mesh_cost = false;
  FuzzyBakeOptions explicit_fine = fixed;
  explicit_fine.kd.intersection_cost = kFineMeshIntersectionCost;
  const FuzzyCharacterData by_default = bake_ok(finer, kd_trees);
  expect_identical(by_default, bake_ok(finer, explicit_fine));
  // The two costs build different trees here, so the comparison above can fail.
  EXPECT_NE(by_default.stats.node_count, bake_ok(finer, fixed).stats.node_count);
  // Below the threshold the default keeps kd.intersection_cost.
  expect_identical(bake_ok(fine, kd_trees), bake_ok(fine, fixed));
}

TEST(FuzzyBakeMemory, TheBudgetBoundsTheBoxStorage) {
  // 40 extra root bones make the vertex x bone boxes the largest buffer.
  Rig rig = arm_rig(4, 6, 26);
  constexpr std::size_t kBones = 44;
  std::vector<Affine3> samples;
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    for (std::size_t b = 0; b < kBones; ++b) samples.push_back(rig.samples[s * 4 + b % 4]);
  }
  rig.samples = samples;
  rig.parents.resize(kBones, -1);
  const std::size_t all_boxes = rig.mesh.vertex_count() * kBones * sizeof(Aabb);
  const FuzzyCharacterData whole = bake_ok(rig);
  EXPECT_GE(whole.stats.peak_bytes, all_boxes);
  FuzzyBakeOptions options;
  options.memory_budget_bytes = all_boxes / 4;
  const FuzzyCharacterData quarter = bake_ok(rig, options);
  EXPECT_LT(quarter.stats.peak_bytes, whole.stats.peak_bytes - all_boxes / 2);
  expect_identical(whole, quarter);
}

// ---------------------------------------------------------------------------
// Trees

TEST_P(FuzzyBakeModes, BoneTreesHoldExactlyTheirBonesTriangles) {
  Rig rig = arm_rig(4, 12, 17);
  // A fifth, separate root bone that no vertex uses: under kInfluencing no
  // triangle can pick it. Under kAll it is moved far away so its boxes are huge.
  rig.parents.push_back(-1);
  std::vector<Affine3> samples;
  Rng rng(18);
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    for (std::size_t b = 0; b < 4; ++b) samples.push_back(rig.samples[s * 4 + b]);
    samples.push_back(to_affine(glm::rotate(glm::dmat4(1.0), rng.uniform(-3, 3), rng.unit_vector()) *
                                glm::translate(glm::dmat4(1.0), glm::dvec3(rng.uniform(-50, 50), 0, 0))));
  }
  rig.samples = samples;
  FuzzyBakeOptions options = with_candidates(GetParam());
  options.bone_trees = BoneTreeKind::kKdTree;  // the BVHs: FuzzyBakeBvh below
  const FuzzyCharacterData data = bake_ok(rig, options);
  const FuzzyCharacterView view = data.view();
  ASSERT_EQ(data.bone_trees.size(), 5u);
  EXPECT_EQ(view.bone_count, 5u);

  std::uint32_t node_cursor = 0;
  std::uint32_t item_cursor = 0;
  std::size_t used_bones = 0;
  for (std::uint32_t b = 0; b < 5; ++b) {
    const BoneTree& tree = data.bone_trees[b];
    EXPECT_EQ(tree.node_begin, node_cursor);
    EXPECT_EQ(tree.item_begin, item_cursor);
    node_cursor += tree.node_count;
    item_cursor += tree.item_count;

    std::set<std::uint32_t> own;
    Aabb bounds;
    for (std::size_t t = 0; t < data.triangle_bone.size(); ++t) {
      if (data.triangle_bone[t] != b) continue;
      own.insert(static_cast<std::uint32_t>(t));
      bounds.extend(triangle_box(data, t));
    }
    EXPECT_EQ(tree.triangle_count, own.size());
    const KdTreeView kd = view.bone_tree(b);
    EXPECT_EQ(kd.nodes.size(), tree.node_count);
    EXPECT_EQ(kd.items.size(), tree.item_count);
    if (own.empty()) {
      EXPECT_TRUE(kd.empty()) << "bone " << b;
      EXPECT_EQ(tree.item_count, 0u);
      EXPECT_TRUE(tree.bounds.is_empty());
      continue;
    }
    ++used_bones;
    ASSERT_FALSE(kd.empty()) << "bone " << b;
    EXPECT_EQ(std::set<std::uint32_t>(kd.items.begin(), kd.items.end()), own) << "bone " << b;
    // Every leaf's items lie inside the slice; leaves reach every item.
    std::set<std::uint32_t> reached;
    for (const KdNode& node : kd.nodes) {
      if (!node.is_leaf()) {
        EXPECT_LT(node.above_child(), kd.nodes.size());
        continue;
      }
      ASSERT_LE(std::size_t{node.first_item()} + node.item_count(), kd.items.size());
      for (std::uint32_t i = 0; i < node.item_count(); ++i) reached.insert(kd.items[node.first_item() + i]);
    }
    EXPECT_EQ(reached, own) << "bone " << b;
    EXPECT_EQ(std::memcmp(&kd.bounds, &bounds, sizeof(Aabb)), 0) << "bone " << b;
  }
  EXPECT_EQ(node_cursor, data.nodes.size());
  EXPECT_EQ(item_cursor, data.items.size());
  EXPECT_EQ(data.bone_trees[4].triangle_count, 0u);
  EXPECT_GE(used_bones, 2u);

  const FuzzyBakeStats& stats = data.stats;
  EXPECT_EQ(stats.bone_count, 5u);
  EXPECT_EQ(stats.sample_count, rig.sample_count());
  EXPECT_EQ(stats.vertex_count, rig.mesh.vertex_count());
  EXPECT_EQ(stats.triangle_count, rig.mesh.triangle_count());
  EXPECT_EQ(stats.candidates, GetParam());
  EXPECT_EQ(stats.node_count, data.nodes.size());
  EXPECT_GE(stats.mean_items_per_leaf, 1.0);
  EXPECT_GE(stats.max_depth, 1);
  EXPECT_GT(stats.peak_bytes, 0u);
  double fuzzy_area = 0.0;
  for (std::size_t t = 0; t < data.triangle_bone.size(); ++t) fuzzy_area += static_cast<double>(triangle_box(data, t).surface_area());
  EXPECT_NEAR(stats.fuzzy_area, fuzzy_area, 1e-4 * fuzzy_area);
}

// ---------------------------------------------------------------------------
// Padding, progress, cancellation

TEST(FuzzyBakePadding, EveryBoxGrowsByTheFractionOfTheBindDiagonal) {
  const Rig rig = arm_rig(3, 10, 19);
  const FuzzyCharacterData plain = bake_ok(rig);
  FuzzyBakeOptions options;
  options.padding = 0.05f;
  const FuzzyCharacterData padded = bake_ok(rig, options);
  // The bind box of the arm: x in [0, 3], y and z in [-0.3, 0.3] (8 segments
  // include the angles 0, 90, 180, 270 degrees).
  const double pad = 0.05 * std::sqrt(3.0 * 3.0 + 0.6 * 0.6 + 0.6 * 0.6);
  std::size_t compared = 0;
  for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
    for (std::uint32_t c = padded.vertex_check_begin[v]; c < padded.vertex_check_begin[v + 1]; ++c) {
      for (std::uint32_t d = plain.vertex_check_begin[v]; d < plain.vertex_check_begin[v + 1]; ++d) {
        if (plain.vertex_checks[d].bone != padded.vertex_checks[c].bone) continue;
        ++compared;
        const Aabb& a = plain.vertex_checks[d].box;
        const Aabb& b = padded.vertex_checks[c].box;
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(static_cast<double>(a.lower[i] - b.lower[i]), pad, 2e-6);
          EXPECT_NEAR(static_cast<double>(b.upper[i] - a.upper[i]), pad, 2e-6);
        }
      }
    }
  }
  EXPECT_GE(compared, rig.mesh.vertex_count());
  EXPECT_GT(padded.stats.fuzzy_area, plain.stats.fuzzy_area);
}

TEST(FuzzyBakeProgress, ReportsEveryPhaseWithRisingFractionsEndingAtOne) {
  const Rig rig = arm_rig(3, 40, 20);
  std::vector<std::pair<std::string, double>> calls;
  FuzzyBakeOptions options;
  options.memory_budget_bytes = 1;
  options.progress = [&](std::string_view phase, double fraction) {
    calls.emplace_back(std::string(phase), fraction);
    return true;
  };
  bake_ok(rig, options);
  ASSERT_GE(calls.size(), 3u);
  std::set<std::string> phases;
  for (std::size_t i = 0; i < calls.size(); ++i) {
    phases.insert(calls[i].first);
    EXPECT_GE(calls[i].second, 0.0);
    EXPECT_LE(calls[i].second, 1.0);
    if (i > 0) {
      EXPECT_GE(calls[i].second, calls[i - 1].second) << "call " << i;
    }
  }
  EXPECT_EQ(phases, (std::set<std::string>{"sampling", "checks", "build"}));
  // Never back to an earlier phase, although the bones came in 3 chunks
  // (sampling and assignment alternate): the phases in order, each once.
  std::vector<std::string> order;
  for (const auto& [phase, fraction] : calls) {
    if (order.empty() || order.back() != phase) order.push_back(phase);
  }
  EXPECT_EQ(order, (std::vector<std::string>{"sampling", "checks", "build"}));
  EXPECT_EQ(calls.back().first, "build");
  EXPECT_EQ(calls.back().second, 1.0);
  EXPECT_LT(calls.front().second, 0.5);
  // 3 chunks plus the check sweep, each over 40 samples in several batches.
  EXPECT_GE(calls.size(), 16u);
}

TEST(FuzzyBakeProgress, ReturningFalseCancelsInAnyPhase) {
  const Rig rig = arm_rig(3, 20, 22);
  for (const char* stop_at : {"sampling", "checks", "build"}) {
    int calls_after_stop = 0;
    bool stopped = false;
    FuzzyBakeOptions options;
    options.progress = [&](std::string_view phase, double) {
      if (stopped) ++calls_after_stop;
      if (phase == stop_at) stopped = true;
      return !stopped;
    };
    JobSystem jobs(2);
    const Expected<FuzzyCharacterData> result = bake_fuzzy_character(rig.input(), options, jobs);
    ASSERT_FALSE(result.ok()) << stop_at;
    EXPECT_EQ(result.status().code(), ErrorCode::kCancelled) << stop_at;
    EXPECT_EQ(calls_after_stop, 0) << stop_at;
  }
}

// ---------------------------------------------------------------------------
// Validation

struct BadInput {
  const char* name;
  std::function<void(Rig&, FuzzyBakeOptions&, FuzzyBakeInput&)> spoil;
  ErrorCode code;
  const char* field;
};

TEST(FuzzyBakeValidation, EveryBadInputIsRejectedNamingItsField) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<BadInput> cases = {
      {"no mesh", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.mesh = nullptr; },
       ErrorCode::kInvalidArgument, "mesh"},
      {"no bones", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.bone_count = 0; },
       ErrorCode::kInvalidArgument, "bone_count"},
      {"too many bones", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.bone_count = 65536; },
       ErrorCode::kLimitExceeded, "bone_count"},
      {"no samples", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.samples = {}; },
       ErrorCode::kInvalidArgument, "samples"},
      {"partial sample", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.samples = in.samples.first(in.samples.size() - 1); },
       ErrorCode::kInvalidArgument, "samples"},
      {"parents size", [](Rig&, FuzzyBakeOptions&, FuzzyBakeInput& in) { in.bone_parents = in.bone_parents.first(2); },
       ErrorCode::kInvalidArgument, "bone_parents"},
      {"parent range", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.parents[2] = 3; },
       ErrorCode::kInvalidArgument, "bone_parents[2]"},
      {"parent below -1", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.parents[1] = -2; },
       ErrorCode::kInvalidArgument, "bone_parents[1]"},
      {"negative padding", [](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.padding = -0.1f; },
       ErrorCode::kInvalidArgument, "padding"},
      {"nan padding", [nan](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.padding = nan; },
       ErrorCode::kInvalidArgument, "padding"},
      {"too many clusters", [](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.pose_clusters = kMaxPoseClusters + 1; },
       ErrorCode::kInvalidArgument, "pose_clusters"},
      {"empty BVH leaves", [](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.bvh.max_leaf_items = 0; },
       ErrorCode::kInvalidArgument, "bvh.max_leaf_items"},
      {"one BVH bin", [](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.bvh.bins = 1; },
       ErrorCode::kInvalidArgument, "bvh.bins"},
      {"unknown bone trees", [](Rig&, FuzzyBakeOptions& o, FuzzyBakeInput&) { o.bone_trees = static_cast<BoneTreeKind>(7); },
       ErrorCode::kInvalidArgument, "bone_trees"},
      {"joint range", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.mesh.joints[7][5] = 3; },
       ErrorCode::kInvalidData, "joints[7][5]"},
      {"joints size", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.mesh.joints.pop_back(); },
       ErrorCode::kInvalidData, "joints"},
      {"weights size", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.mesh.weights.emplace_back(); },
       ErrorCode::kInvalidData, "weights"},
      {"nan weight", [nan](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.mesh.weights[4][1] = nan; },
       ErrorCode::kInvalidData, "weights[4][1]"},
      {"inf position", [inf](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.mesh.positions[9].y = inf; },
       ErrorCode::kInvalidData, "positions[9]"},
      {"triangle range", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) {
         rig.mesh.triangles[5][2] = static_cast<std::uint32_t>(rig.mesh.vertex_count()); },
       ErrorCode::kInvalidData, "triangles[5][2]"},
      {"nan sample", [nan](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) { rig.samples[3 * 3 + 1].rows[2].w = nan; },
       ErrorCode::kInvalidData, "samples[3].bone[1]"},
      {"zero-scale sample", [](Rig& rig, FuzzyBakeOptions&, FuzzyBakeInput&) {
         rig.samples[4 * 3 + 2].rows[1] = Vec4(0.0f, 0.0f, 0.0f, 1.0f); },
       ErrorCode::kInvalidData, "samples[4].bone[2]"},
  };
  for (const BadInput& bad : cases) {
    Rig rig = arm_rig(3, 6, 23);
    FuzzyBakeOptions options;
    FuzzyBakeInput input = rig.input();
    bad.spoil(rig, options, input);
    JobSystem jobs(1);
    const Expected<FuzzyCharacterData> result = bake_fuzzy_character(input, options, jobs);
    ASSERT_FALSE(result.ok()) << bad.name;
    EXPECT_EQ(result.status().code(), bad.code) << bad.name << ": " << result.status().message();
    EXPECT_EQ(result.status().field(), bad.field) << bad.name << ": " << result.status().message();
  }
}

// ---------------------------------------------------------------------------
// Pose-space clusters (FuzzyBakeOptions::pose_clusters)

FuzzyBakeOptions with_clusters(std::uint32_t k) {
  FuzzyBakeOptions options;
  options.pose_clusters = k;
  return options;
}

// The cluster a frame picks for bone b in sampled pose s, as the scene does
// (frame_state.cpp): the feature from inverse(S_b) and S, the nearest centre.
int runtime_cluster(const FuzzyCharacterView& fuzzy, const Rig& rig, std::size_t s, std::uint32_t b) {
  const std::span<const std::uint16_t> feature_bones = fuzzy.bone_feature_bones(b);
  std::vector<float> feature(feature_bones.size() * kClusterFeatureFloats);
  cluster_feature(inverse(rig.pose(s)[b]), rig.pose(s), feature_bones, fuzzy.feature_translation_scale, feature.data());
  return nearest_cluster(fuzzy.bone_clusters(b), fuzzy.cluster_centres, feature);
}

TEST(FuzzyBakeClusters, KMeansSplitsApartGroupsAndKeepsOnlyDistinctPoints) {
  // Two groups around (0, 0) and (10, 0): two clusters, whatever k above 1.
  const std::vector<float> points = {0.0f, 0.0f, 0.5f, 0.0f, 0.0f, 0.5f, 10.0f, 0.0f, 10.5f, 0.0f, 10.0f, 0.5f};
  std::vector<std::uint32_t> member;
  std::vector<float> centres;
  ASSERT_EQ(cluster_points(points, 6, 2, 2, member, centres), 2u);
  EXPECT_EQ(member[0], member[1]);
  EXPECT_EQ(member[1], member[2]);
  EXPECT_EQ(member[3], member[4]);
  EXPECT_EQ(member[4], member[5]);
  EXPECT_NE(member[0], member[3]);
  // The centres are the groups' means (hand-computed: 1/6 and 10 + 1/6).
  const std::size_t low = member[0];
  EXPECT_FLOAT_EQ(centres[low * 2], 0.5f / 3.0f);
  EXPECT_FLOAT_EQ(centres[low * 2 + 1], 0.5f / 3.0f);
  EXPECT_FLOAT_EQ(centres[(1 - low) * 2], 10.0f + 0.5f / 3.0f);
  // Three distinct values among six points: at most three clusters for any k.
  const std::vector<float> repeated = {1.0f, 1.0f, 2.0f, 2.0f, 3.0f, 3.0f};
  EXPECT_EQ(cluster_points(repeated, 6, 1, 8, member, centres), 3u);
  EXPECT_EQ(member[0], member[1]);
  EXPECT_NE(member[1], member[2]);
  EXPECT_EQ(cluster_points(repeated, 6, 1, 1, member, centres), 1u);
  EXPECT_EQ(cluster_points({}, 0, 1, 4, member, centres), 0u);
}

// The conservativeness invariant for every tree a bone may choose: in each
// sampled pose, the cluster the frame picks holds every vertex of the bone's
// checks (against the double-precision skinning), its tree lists every
// triangle where its box needs it (validate_fuzzy_character), and the
// cluster's boxes lie inside the full ones and are smaller in sum.
TEST(FuzzyBakeClusters, EverySampledPoseLiesInTheClusterItsBonesPick) {
  const Rig rig = arm_rig(5, 60, 31);
  const FuzzyCharacterData data = bake_ok(rig, with_clusters(6));
  const FuzzyCharacterView fuzzy = data.view();
  ASSERT_TRUE(validate_fuzzy_character(rig.mesh, fuzzy).ok());
  ASSERT_TRUE(fuzzy.has_clusters());
  EXPECT_EQ(data.stats.cluster_count, data.clusters.size());
  EXPECT_LT(data.stats.cluster_fuzzy_area, 0.8 * data.stats.fuzzy_area);
  const RefSamples ref = reference_samples(rig);
  std::size_t held = 0;
  for (std::size_t s = 0; s < rig.sample_count(); ++s) {
    for (std::size_t v = 0; v < rig.mesh.vertex_count(); ++v) {
      for (std::uint32_t c = data.vertex_check_begin[v]; c < data.vertex_check_begin[v + 1]; ++c) {
        const std::uint32_t b = data.vertex_checks[c].bone;
        if (fuzzy.bone_clusters(b).empty()) continue;
        const int k = runtime_cluster(fuzzy, rig, s, b);
        ASSERT_GE(k, 0);
        const BoneCluster& cluster = fuzzy.bone_clusters(b)[static_cast<std::size_t>(k)];
        const Aabb& box = fuzzy.cluster_check_box(cluster, c);
        const glm::dvec3 p = apply(ref.bone_from_pose[s][b], ref.skinned[s][v]);
        ASSERT_TRUE(box_contains(box, p)) << "sample " << s << " vertex " << v << " bone " << b << " cluster " << k;
        for (int a = 0; a < 3; ++a) {
          EXPECT_GE(box.lower[a], data.vertex_checks[c].box.lower[a]);
          EXPECT_LE(box.upper[a], data.vertex_checks[c].box.upper[a]);
        }
        ++held;
      }
    }
  }
  EXPECT_GT(held, 0u);
}

// With either kind of bone tree (docs/RAYTRACE.md "Bone trees: kd-tree or BVH").
class FuzzyBakeTreeKinds : public ::testing::TestWithParam<BoneTreeKind> {};

INSTANTIATE_TEST_SUITE_P(FuzzyBake, FuzzyBakeTreeKinds, ::testing::Values(BoneTreeKind::kKdTree, BoneTreeKind::kBvh),
                         [](const ::testing::TestParamInfo<BoneTreeKind>& kind) {
                           return kind.param == BoneTreeKind::kBvh ? std::string("Bvh") : std::string("KdTree");
                         });

TEST_P(FuzzyBakeTreeKinds, ThreadCountDoesNotChangeTheClusters) {
  const Rig rig = arm_rig(5, 40, 32);
  FuzzyBakeOptions options = with_clusters(5);
  options.bone_trees = GetParam();
  const FuzzyCharacterData a = bake_ok(rig, options, 1);
  const FuzzyCharacterData b = bake_ok(rig, options, 3);
  expect_identical(a, b);  // the cluster arrays too
  // Without clusters the bake is the one it always was.
  FuzzyBakeOptions plain;
  plain.bone_trees = GetParam();
  const FuzzyCharacterData none = bake_ok(rig, plain, 2);
  EXPECT_TRUE(none.clusters.empty());
  EXPECT_TRUE(none.cluster_boxes.empty());
  if (GetParam() == BoneTreeKind::kBvh) {
    ASSERT_GT(a.bvh_nodes.size(), none.bvh_nodes.size());
    expect_same_bytes(std::vector<BvhNode>(a.bvh_nodes.begin(),
                                           a.bvh_nodes.begin() + static_cast<std::ptrdiff_t>(none.bvh_nodes.size())),
                      none.bvh_nodes, "the full trees' nodes come first, as without clusters");
  } else {
    ASSERT_GT(a.nodes.size(), none.nodes.size());
    expect_same_bytes(
        std::vector<KdNode>(a.nodes.begin(), a.nodes.begin() + static_cast<std::ptrdiff_t>(none.nodes.size())),
        none.nodes, "the full trees' nodes come first, as without clusters");
  }
  expect_same_bytes(a.bone_trees, none.bone_trees, "full trees with and without clusters");
  expect_same_bytes(a.vertex_checks, none.vertex_checks, "checks with and without clusters");
}

// A scene on the clusters: sampled poses use cluster trees and never miss;
// poses far outside the pose space miss, fall back to the full trees (and
// the escape fallback), and still trace exactly as brute force.
TEST_P(FuzzyBakeTreeKinds, ScenesUseClusterTreesAndStayExactOutsideThePoseSpace) {
  const Rig rig = arm_rig(5, 40, 33);
  FuzzyBakeOptions options = with_clusters(6);
  options.bone_trees = GetParam();
  options.bvh.max_leaf_items = 3;
  const FuzzyCharacterData data = bake_ok(rig, options);
  ASSERT_EQ(data.tree_kind, GetParam());
  Scene scene;
  auto character = scene.add_character(rig.mesh, data.view());
  ASSERT_TRUE(character.ok()) << character.status().message();
  ASSERT_TRUE(scene.add_instance(*character).ok());
  JobSystem jobs(2);
  const std::vector<Affine3> wild = chain_poses(rig.parents, 6, 3.0, 77, false);
  Rng rng(5);
  std::size_t checked = 0, wrong = 0, misses = 0;
  for (std::size_t k = 0; k < 16; ++k) {
    const bool outside = k >= 10;
    const std::span<const Affine3> pose =
        outside ? std::span<const Affine3>(wild).subspan((k - 10) * rig.parents.size(), rig.parents.size())
                : rig.pose(k * 3);
    ASSERT_TRUE(scene.set_bones(0, pose).ok());
    auto stats = scene.prepare_frame(FrameOptions{}, jobs);
    ASSERT_TRUE(stats.ok()) << stats.status().message();
    if (!outside) {
      EXPECT_EQ(stats->cluster_misses, 0u) << "sample " << k * 3;
      EXPECT_EQ(stats->escaped_checks, 0u) << "sample " << k * 3;
      EXPECT_GT(stats->cluster_bones, 0u) << "sample " << k * 3;
    }
    misses += stats->cluster_misses;
    const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(scene);
    for (int i = 0; i < 400; ++i) {
      const glm::dvec3 o = glm::dvec3(rng.uniform(-3, 8), rng.uniform(-4, 4), rng.uniform(-4, 4));
      const testing_support::SoupTriangle& tri = soup[static_cast<std::size_t>(i) % soup.size()];
      Ray ray;
      ray.origin = Vec3(o);
      ray.direction = (tri.p0 + tri.p1 + tri.p2) / 3.0f - ray.origin;
      for (const TriangleTest test : {TriangleTest::kFast, TriangleTest::kWatertight}) {
        const Hit ours = intersect(scene, ray, test);
        const Hit ref = testing_support::nearest(soup, ray, test);
        ++checked;
        if (!testing_support::same_nearest(ours, ref, soup, ray, test)) ++wrong;
      }
    }
  }
  EXPECT_GT(misses, 0u) << "the wild poses should leave some cluster";
  EXPECT_EQ(wrong, 0u) << "of " << checked << " rays";
}

// Every BVH (each bone's full tree and each cluster's) lists its bone's
// triangles exactly once, and every node box on a triangle's path holds the
// triangle's fuzzy box for that tree (the union of its corners' boxes, the
// cluster's where the cluster has its own): what makes a walk that enters
// every box a ray passes reach every triangle the ray may hit.
TEST(FuzzyBakeBvh, EveryTreeListsItsBonesTrianglesOnceInsideEveryBoxAbove) {
  const Rig rig = arm_rig(5, 60, 35);
  FuzzyBakeOptions options = with_clusters(4);
  options.bone_trees = BoneTreeKind::kBvh;
  options.bvh.max_leaf_items = 2;
  const FuzzyCharacterData data = bake_ok(rig, options);
  const FuzzyCharacterView view = data.view();
  ASSERT_TRUE(view.has_bvhs());
  EXPECT_TRUE(data.nodes.empty());
  ASSERT_TRUE(validate_fuzzy_character(rig.mesh, view).ok());
  ASSERT_FALSE(data.clusters.empty());
  struct Tree {
    const BoneTree* slice;
    std::uint32_t bone;
    const BoneCluster* cluster;  // null: the full tree
  };
  std::vector<Tree> trees;
  // The bones' full trees, then the clusters' (in bone order).
  for (std::uint32_t b = 0; b < data.bone_count; ++b) trees.push_back({&data.bone_trees[b], b, nullptr});
  for (std::uint32_t b = 0; b < data.bone_count; ++b) {
    for (const BoneCluster& c : view.bone_clusters(b)) trees.push_back({&c.tree, b, &c});
  }
  std::uint32_t node_cursor = 0, item_cursor = 0;
  int inner_nodes = 0;
  for (const Tree& tree : trees) {
    EXPECT_EQ(tree.slice->node_begin, node_cursor);
    EXPECT_EQ(tree.slice->item_begin, item_cursor);
    node_cursor += tree.slice->node_count;
    item_cursor += tree.slice->item_count;
    std::multiset<std::uint32_t> own;
    for (std::size_t t = 0; t < data.triangle_bone.size(); ++t) {
      if (data.triangle_bone[t] == tree.bone) own.insert(static_cast<std::uint32_t>(t));
    }
    const BvhView bvh = view.bvh_view(*tree.slice);
    std::multiset<std::uint32_t> listed;
    // Depth first with each node's ancestors' boxes.
    std::vector<std::pair<std::uint32_t, std::vector<Aabb>>> stack;
    if (!bvh.empty()) stack.push_back({0u, {}});
    while (!stack.empty()) {
      auto [n, above] = stack.back();
      stack.pop_back();
      const BvhNode& node = bvh.nodes[n];
      above.push_back(node.box);
      if (!node.is_leaf()) {
        ++inner_nodes;
        stack.push_back({node.first, above});
        stack.push_back({node.first + 1, above});
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t t = bvh.items[i];
        listed.insert(t);
        Aabb box;
        for (const std::uint32_t c : data.triangle_checks[t]) {
          box.extend(tree.cluster ? view.cluster_check_box(*tree.cluster, c) : data.vertex_checks[c].box);
        }
        for (const Aabb& a : above) {
          for (int axis = 0; axis < 3; ++axis) {
            EXPECT_LE(a.lower[axis], box.lower[axis]) << "triangle " << t << " of bone " << tree.bone;
            EXPECT_GE(a.upper[axis], box.upper[axis]) << "triangle " << t << " of bone " << tree.bone;
          }
        }
      }
    }
    EXPECT_EQ(listed, own) << "bone " << tree.bone << (tree.cluster ? " (a cluster)" : " (full)");
  }
  EXPECT_EQ(node_cursor, data.bvh_nodes.size());
  EXPECT_EQ(item_cursor, data.items.size());
  EXPECT_GT(inner_nodes, 0);
  EXPECT_EQ(data.stats.node_count, data.bvh_nodes.size());
  EXPECT_LE(data.stats.mean_items_per_leaf, 2.0);
}

TEST(FuzzyBakeClusters, CorruptClusterDataIsRefusedNamingTheField) {
  const Rig rig = arm_rig(4, 30, 34);
  const FuzzyCharacterData good = bake_ok(rig, with_clusters(4));
  ASSERT_FALSE(good.clusters.empty());
  struct Case {
    const char* name;
    std::function<void(FuzzyCharacterData&)> spoil;
    const char* field;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Case> cases = {
      {"box range", [](FuzzyCharacterData& d) { d.clusters.back().box_begin = static_cast<std::uint32_t>(d.cluster_boxes.size()); },
       "clusters[" },
      {"rank", [](FuzzyCharacterData& d) {
         for (std::size_t c = 0; c < d.check_rank.size(); ++c) {
           const std::uint32_t b = d.vertex_checks[c].bone;
           if (d.bone_cluster_begin[b] != d.bone_cluster_begin[b + 1]) {
             d.check_rank[c] = 1u << 30;
             return;
           }
         } },
       "check_rank["},
      {"nan box", [nan](FuzzyCharacterData& d) { d.cluster_boxes[0].lower.y = nan; }, "cluster_boxes[0]"},
      {"nan centre", [nan](FuzzyCharacterData& d) { d.cluster_centres[0] = nan; }, "cluster_centres[0]"},
      {"feature bone", [](FuzzyCharacterData& d) { d.feature_bones[0] = 999; }, "feature_bones[0]"},
      {"offsets", [](FuzzyCharacterData& d) { d.bone_cluster_begin.pop_back(); }, "bone_cluster_begin"},
      {"shrunk tree", [](FuzzyCharacterData& d) {
         BoneTree& t = d.clusters.back().tree;
         t.bounds.upper.x = t.bounds.lower.x; },
       "clusters["},
      {"scale", [](FuzzyCharacterData& d) { d.feature_translation_scale = 0.0f; }, "feature_translation_scale"},
  };
  for (const Case& c : cases) {
    FuzzyCharacterData bad = good;
    c.spoil(bad);
    const Status status = validate_fuzzy_character(rig.mesh, bad.view());
    ASSERT_FALSE(status.ok()) << c.name;
    EXPECT_EQ(status.code(), ErrorCode::kInvalidData) << c.name;
    EXPECT_EQ(std::string(status.field()).rfind(c.field, 0), 0u) << c.name << ": " << status.message();
  }
}

TEST(FuzzyBakeValidation, AMeshWithoutTrianglesBakesToEmptyTrees) {
  Rig rig = arm_rig(3, 4, 24);
  rig.mesh.triangles.clear();
  const FuzzyCharacterData data = bake_ok(rig);
  EXPECT_TRUE(data.triangle_bone.empty());
  EXPECT_TRUE(data.vertex_checks.empty());
  EXPECT_EQ(data.vertex_check_begin.size(), rig.mesh.vertex_count() + 1);
  ASSERT_EQ(data.bone_trees.size(), 3u);
  for (const BoneTree& tree : data.bone_trees) EXPECT_EQ(tree.node_count, 0u);
  EXPECT_EQ(data.stats.fuzzy_area, 0.0);
}

// ---------------------------------------------------------------------------
// Measurement (not a test): run with --gtest_also_run_disabled_tests
// --gtest_filter='FuzzyBakeBench*'.

TEST(FuzzyBakeBench, DISABLED_TenThousandTrianglesTwentyBones) {
  Rig rig;
  rig.mesh = arm_mesh(20, 25, 0.1);  // 200 ring gaps x 50 triangles = 10k triangles
  rig.parents = chain_parents(20);
  rig.samples = chain_poses(rig.parents, 200, 0.8, 25, false);
  JobSystem jobs;
  for (CandidateBones mode : {CandidateBones::kAll, CandidateBones::kInfluencing}) {
    const auto start = std::chrono::steady_clock::now();
    const Expected<FuzzyCharacterData> result = bake_fuzzy_character(rig.input(), with_candidates(mode), jobs);
    const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(result.ok()) << result.status().message();
    const FuzzyBakeStats& s = result->stats;
    std::printf("%s: %u tris, %u verts, %u bones, %u samples, %d threads: sampling %.1f ms, assignment %.1f ms, "
                "build %.1f ms, total %.1f ms; fuzzy area %.2f (rest %.2f), %.2f items/leaf, depth %d, "
                "%u nodes, peak %.2f MiB\n",
                mode == CandidateBones::kAll ? "kAll" : "kInfluencing", s.triangle_count, s.vertex_count,
                s.bone_count, s.sample_count, jobs.thread_count(), s.sampling_ms, s.assignment_ms, s.build_ms,
                total, s.fuzzy_area, s.rest_area, s.mean_items_per_leaf, s.max_depth, s.node_count,
                static_cast<double>(s.peak_bytes) / (1024.0 * 1024.0));
  }
}

}  // namespace
}  // namespace sinew::rt
