// The procedural mannequin: skeleton shape, mesh validity (closed, outward
// normals, skin weights), rest-pose skinning, clips and joint limits.
#include "content/mannequin/mannequin.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "animation/pose.h"
#include "animation/reference_skinning.h"

namespace sinew::content {
namespace {

const character::Model& model() {
  static const character::Model m = *make_mannequin();
  return m;
}

std::vector<anim::JointTransform> sample(const anim::Clip& clip, float t) {
  const anim::Skeleton& sk = model().skeleton;
  std::vector<anim::JointTransform> local(sk.joint_count());
  EXPECT_TRUE(anim::rest_pose(sk, local).ok());
  anim::SamplingCache cache;
  anim::sample_clip(clip, t, cache, local);
  return local;
}

std::vector<Affine3> to_model(std::span<const anim::JointTransform> local) {
  std::vector<Affine3> m(local.size());
  EXPECT_TRUE(anim::local_to_model(model().skeleton, local, m).ok());
  return m;
}

// Closest point to p on segment [a, b].
Vec3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + ab * t;
}

TEST(Mannequin, RejectsBadOptions) {
  EXPECT_FALSE(make_mannequin({.detail = 0}).ok());
  EXPECT_FALSE(make_mannequin({.detail = 17}).ok());
  EXPECT_FALSE(make_mannequin({.detail = 1, .height = -1.0f}).ok());
  EXPECT_FALSE(make_mannequin({.detail = 1, .height = NAN}).ok());
}

TEST(Mannequin, SkeletonHasTheExpectedJoints) {
  const auto& sk = model().skeleton;
  EXPECT_GE(sk.joint_count(), 18u);
  EXPECT_LE(sk.joint_count(), 24u);
  for (const char* name : {"pelvis", "spine", "chest", "neck", "head", "clavicle_l", "upperarm_l",
                           "lowerarm_l", "hand_l", "clavicle_r", "upperarm_r", "lowerarm_r",
                           "hand_r", "thigh_l", "calf_l", "foot_l", "toe_l", "thigh_r", "calf_r",
                           "foot_r", "toe_r"}) {
    EXPECT_TRUE(sk.find(name).has_value()) << name;
  }
  EXPECT_EQ(model().source, "mannequin");
}

TEST(Mannequin, TriangleCountFollowsDetail) {
  EXPECT_GE(model().mesh.triangle_count(), 2800u);
  EXPECT_LE(model().mesh.triangle_count(), 3500u);
  const auto fine = make_mannequin({.detail = 2});
  ASSERT_TRUE(fine.ok()) << fine.status().message();
  EXPECT_EQ(fine->mesh.triangle_count(), 4 * model().mesh.triangle_count());
}

TEST(Mannequin, MeshArraysAreConsistent) {
  const SkinnedMesh& mesh = model().mesh;
  const std::size_t n = mesh.vertex_count();
  EXPECT_EQ(mesh.normals.size(), n);
  EXPECT_EQ(mesh.joints.size(), n);
  EXPECT_EQ(mesh.weights.size(), n);
  EXPECT_EQ(mesh.triangle_material.size(), mesh.triangle_count());
  EXPECT_EQ(mesh.material_colors.size(), model().material_names.size());
  EXPECT_EQ(model().material_names,
            (std::vector<std::string>{"skin", "shirt", "trousers", "shoes"}));
  std::set<std::uint32_t> used;
  for (const std::uint32_t m : mesh.triangle_material) {
    ASSERT_LT(m, mesh.material_colors.size());
    used.insert(m);
  }
  EXPECT_EQ(used.size(), mesh.material_colors.size());
}

TEST(Mannequin, WeightsSumToOneAndIndicesAreValid) {
  const SkinnedMesh& mesh = model().mesh;
  const std::size_t joints = model().skeleton.joint_count();
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    float sum = 0.0f;
    for (int i = 0; i < kMaxInfluences; ++i) {
      const float w = mesh.weights[v][static_cast<std::size_t>(i)];
      EXPECT_GE(w, 0.0f);
      EXPECT_LT(mesh.joints[v][static_cast<std::size_t>(i)], joints);
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0f, 1e-5f) << "vertex " << v;
  }
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t i : tri) ASSERT_LT(i, mesh.vertex_count());
  }
}

TEST(Mannequin, MeshIsClosedWithoutDegenerateTriangles) {
  const SkinnedMesh& mesh = model().mesh;
  // Directed edges: a closed, consistently wound surface uses each directed
  // edge once and its reverse once.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  std::set<std::array<std::uint32_t, 3>> seen;
  for (const auto& tri : mesh.triangles) {
    EXPECT_NE(tri[0], tri[1]);
    EXPECT_NE(tri[1], tri[2]);
    EXPECT_NE(tri[0], tri[2]);
    const Vec3 n = glm::cross(mesh.positions[tri[1]] - mesh.positions[tri[0]],
                              mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    EXPECT_GT(glm::length(n), 1e-9f);
    auto key = tri;
    std::sort(key.begin(), key.end());
    EXPECT_TRUE(seen.insert(key).second) << "duplicate triangle";
    for (int e = 0; e < 3; ++e) {
      ++directed[{tri[static_cast<std::size_t>(e)], tri[static_cast<std::size_t>((e + 1) % 3)]}];
    }
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    const auto reverse = directed.find({edge.second, edge.first});
    ASSERT_NE(reverse, directed.end()) << "open edge " << edge.first << "-" << edge.second;
    EXPECT_EQ(reverse->second, 1);
  }
}

TEST(Mannequin, NormalsAreUnitAndPointOutwards) {
  const SkinnedMesh& mesh = model().mesh;
  const auto& sk = model().skeleton;
  std::vector<anim::JointTransform> local(sk.joint_count());
  ASSERT_TRUE(anim::rest_pose(sk, local).ok());
  const std::vector<Affine3> joints = to_model(local);
  std::size_t outward = 0;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_NEAR(glm::length(mesh.normals[v]), 1.0f, 1e-4f);
    const Vec3 p = mesh.positions[v];
    // Nearest point on any bone segment (joint to parent).
    Vec3 best(0.0f);
    float best_d = 1e30f;
    for (std::size_t j = 0; j < sk.joint_count(); ++j) {
      const int parent = sk.parents()[j];
      if (parent == anim::kNoParent) continue;
      const Vec3 q = closest_on_segment(p, joints[static_cast<std::size_t>(parent)].translation_part(),
                                        joints[j].translation_part());
      const float d = glm::length(p - q);
      if (d < best_d) {
        best_d = d;
        best = q;
      }
    }
    if (glm::dot(mesh.normals[v], p - best) > 0.0f) ++outward;
  }
  EXPECT_GT(static_cast<double>(outward), 0.95 * static_cast<double>(mesh.vertex_count()));
}

TEST(Mannequin, RestPoseFigureHasTheRequestedHeight) {
  for (const float height : {1.8f, 1.5f}) {
    const auto m = make_mannequin({.detail = 1, .height = height});
    ASSERT_TRUE(m.ok());
    float lo = 1e30f;
    float hi = -1e30f;
    for (const Vec3& p : m->mesh.positions) {
      lo = std::min(lo, p.y);
      hi = std::max(hi, p.y);
    }
    EXPECT_NEAR(lo, 0.0f, 0.005f * height);
    EXPECT_NEAR(hi, height, 0.01f * height);
  }
}

TEST(Mannequin, RestPoseSkinningReproducesTheMesh) {
  const auto& sk = model().skeleton;
  const SkinnedMesh& mesh = model().mesh;
  std::vector<anim::JointTransform> local(sk.joint_count());
  ASSERT_TRUE(anim::rest_pose(sk, local).ok());
  const std::vector<Affine3> joints = to_model(local);
  std::vector<Affine3> skin(sk.joint_count());
  ASSERT_TRUE(anim::skinning_matrices(sk, joints, Affine3::identity(), skin).ok());
  std::vector<Vec3> positions(mesh.vertex_count());
  std::vector<Vec3> normals(mesh.vertex_count());
  ASSERT_TRUE(anim::skin_reference(mesh, skin, positions, normals).ok());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_LT(glm::length(positions[v] - mesh.positions[v]), 1e-5f);
    EXPECT_LT(glm::length(normals[v] - mesh.normals[v]), 1e-5f);
  }
}

TEST(Mannequin, ClipsBuildWithTheirNames) {
  const auto& clips = model().clips;
  ASSERT_EQ(clips.size(), 5u);
  const std::vector<std::string> names{"idle", "walk", "run", "wave", "kick"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(clips[i].name(), names[i]);
    EXPECT_GT(clips[i].duration(), 0.0f);
    EXPECT_NE(model().find_clip(names[i]), nullptr);
  }
  EXPECT_NEAR(model().find_clip("walk")->duration(), 1.0f, 1e-6f);
  EXPECT_LT(model().find_clip("run")->duration(), 1.0f);
}

TEST(Mannequin, LoopClipsStartAndEndOnTheSamePose) {
  for (const char* name : {"idle", "walk", "run"}) {
    const anim::Clip& clip = *model().find_clip(name);
    const auto first = sample(clip, 0.0f);
    const auto last = sample(clip, clip.duration());
    for (std::size_t j = 0; j < first.size(); ++j) {
      EXPECT_LT(glm::length(first[j].translation - last[j].translation), 1e-6f) << name;
      EXPECT_GT(std::abs(glm::dot(first[j].rotation, last[j].rotation)), 1.0f - 1e-6f) << name;
    }
  }
}

TEST(Mannequin, OneShotClipsStartAndEndAtRest) {
  const auto rest = model().skeleton.rest_pose();
  for (const char* name : {"wave", "kick"}) {
    const anim::Clip& clip = *model().find_clip(name);
    for (const float t : {0.0f, clip.duration()}) {
      const auto pose = sample(clip, t);
      for (std::size_t j = 0; j < pose.size(); ++j) {
        EXPECT_GT(std::abs(glm::dot(pose[j].rotation, rest[j].rotation)), 1.0f - 1e-6f) << name;
      }
    }
  }
}

TEST(Mannequin, WaveAnimatesOnlyTheUpperBody) {
  const auto& sk = model().skeleton;
  for (const anim::JointTracks& tracks : model().find_clip("wave")->tracks()) {
    const std::string& name = sk.names()[static_cast<std::size_t>(tracks.joint)];
    EXPECT_EQ(name.find("thigh"), std::string::npos);
    EXPECT_EQ(name.find("calf"), std::string::npos);
    EXPECT_EQ(name.find("foot"), std::string::npos);
    EXPECT_NE(name, "pelvis");
  }
}

float foot_travel(const char* clip_name, const char* joint) {
  const anim::Clip& clip = *model().find_clip(clip_name);
  const auto foot = static_cast<std::size_t>(*model().skeleton.find(joint));
  float lo = 1e30f;
  float hi = -1e30f;
  for (int i = 0; i <= 60; ++i) {
    const auto m = to_model(sample(clip, clip.duration() * static_cast<float>(i) / 60.0f));
    const float z = m[foot].translation_part().z;
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  return hi - lo;
}

TEST(Mannequin, WalkMovesTheFeet) {
  EXPECT_GT(foot_travel("walk", "foot_l"), 0.2f);
  EXPECT_GT(foot_travel("walk", "foot_r"), 0.2f);
  EXPECT_GT(foot_travel("run", "foot_l"), foot_travel("walk", "foot_l"));
  EXPECT_GT(foot_travel("kick", "foot_r"), 0.3f);
}

TEST(Mannequin, FeetStayAboveTheFloorWhileWalking) {
  // The walk is in place: a foot may lift but should not sink far below y=0.
  const anim::Clip& clip = *model().find_clip("walk");
  for (int i = 0; i <= 30; ++i) {
    const auto m = to_model(sample(clip, static_cast<float>(i) / 30.0f));
    for (const char* name : {"foot_l", "foot_r"}) {
      const float y = m[static_cast<std::size_t>(*model().skeleton.find(name))].translation_part().y;
      EXPECT_GT(y, 0.0f) << name << " at " << i;
    }
  }
}

TEST(Mannequin, IsDeterministic) {
  const auto a = make_mannequin();
  const auto b = make_mannequin();
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->mesh.positions, b->mesh.positions);
  EXPECT_EQ(a->mesh.normals, b->mesh.normals);
  EXPECT_EQ(a->mesh.weights, b->mesh.weights);
  EXPECT_EQ(a->mesh.joints, b->mesh.joints);
  EXPECT_EQ(a->mesh.triangles, b->mesh.triangles);
  ASSERT_EQ(a->clips.size(), b->clips.size());
  for (std::size_t c = 0; c < a->clips.size(); ++c) {
    const auto ta = a->clips[c].tracks();
    const auto tb = b->clips[c].tracks();
    ASSERT_EQ(ta.size(), tb.size());
    for (std::size_t i = 0; i < ta.size(); ++i) {
      EXPECT_EQ(ta[i].rotation.values, tb[i].rotation.values);
      EXPECT_EQ(ta[i].translation.values, tb[i].translation.values);
    }
  }
}

TEST(Mannequin, JointLimitsCoverTheSkeleton) {
  const auto& sk = model().skeleton;
  const anim::JointLimits limits = mannequin_joint_limits(sk);
  ASSERT_EQ(limits.size(), sk.joint_count());
  EXPECT_EQ(limits[static_cast<std::size_t>(*sk.find("pelvis"))].kind, anim::LimitKind::kFree);
  EXPECT_EQ(limits[static_cast<std::size_t>(*sk.find("calf_l"))].kind, anim::LimitKind::kEuler);
  EXPECT_EQ(limits[static_cast<std::size_t>(*sk.find("upperarm_r"))].kind,
            anim::LimitKind::kSwingTwist);
  for (const anim::JointLimit& l : limits) {
    if (l.kind != anim::LimitKind::kEuler) continue;
    for (int a = 0; a < 3; ++a) EXPECT_LE(l.euler.min[a], l.euler.max[a]);
  }
}

TEST(Mannequin, ClipPosesStayWithinJointLimits) {
  const auto& sk = model().skeleton;
  const anim::JointLimits limits = mannequin_joint_limits(sk);
  EXPECT_TRUE(anim::validate_joint_limits(limits, "mannequin").ok());
  for (const anim::Clip& clip : model().clips) {
    for (int i = 0; i <= 120; ++i) {
      const float t = clip.duration() * static_cast<float>(i) / 120.0f;
      const auto pose = sample(clip, t);
      for (std::size_t j = 0; j < pose.size(); ++j) {
        // Rest rotations are the identity, so the local rotation is the delta.
        const Quat delta = glm::inverse(sk.rest_pose()[j].rotation) * pose[j].rotation;
        EXPECT_TRUE(anim::is_within(limits[j], delta, 1e-3f))
            << clip.name() << " t=" << t << " joint " << sk.names()[j];
      }
    }
  }
}

TEST(Mannequin, JointLimitsRejectImplausibleRotations) {
  const auto& sk = model().skeleton;
  const anim::JointLimits limits = mannequin_joint_limits(sk);
  const auto limit = [&](const char* name) {
    return limits[static_cast<std::size_t>(*sk.find(name))];
  };
  const float a = 0.5f;  // about 29 degrees
  // Knees bend backwards only; elbows forwards only.
  EXPECT_TRUE(anim::is_within(limit("calf_l"), glm::angleAxis(a, Vec3(1, 0, 0))));
  EXPECT_FALSE(anim::is_within(limit("calf_l"), glm::angleAxis(-a, Vec3(1, 0, 0))));
  EXPECT_FALSE(anim::is_within(limit("calf_l"), glm::angleAxis(a, Vec3(0, 0, 1))));
  EXPECT_TRUE(anim::is_within(limit("lowerarm_l"), glm::angleAxis(-a, Vec3(0, 1, 0))));
  EXPECT_FALSE(anim::is_within(limit("lowerarm_l"), glm::angleAxis(a, Vec3(0, 1, 0))));
  EXPECT_TRUE(anim::is_within(limit("lowerarm_r"), glm::angleAxis(a, Vec3(0, 1, 0))));
  EXPECT_FALSE(anim::is_within(limit("lowerarm_r"), glm::angleAxis(-a, Vec3(0, 1, 0))));
  // The neck does not turn all the way round.
  EXPECT_FALSE(anim::is_within(limit("neck"), glm::angleAxis(2.0f, Vec3(0, 1, 0))));
}

}  // namespace
}  // namespace sinew::content
