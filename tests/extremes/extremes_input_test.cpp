// Extreme inputs end to end (docs/ROBUSTNESS.md): clips with duplicate,
// out-of-order or single keys, and skin weights that do not sum to 1. Each
// either gives the brute-force image after bake and render, or a clear error
// naming the field.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "animation/clip.h"
#include "character/bake.h"
#include "character/model.h"
#include "content/mannequin/mannequin.h"
#include "tests/extremes/extremes_support.h"

namespace sinew::extremes {
namespace {

// A rotation track raising the left upper arm, with the given key times.
anim::RawClip arm_clip(const anim::Skeleton& skeleton, std::vector<float> times) {
  anim::RawClip raw;
  raw.name = "raise";
  anim::JointTracks jt;
  jt.joint = *skeleton.find("upperarm_l");
  for (std::size_t k = 0; k < times.size(); ++k) {
    const float angle = 0.3f * static_cast<float>(k + 1);
    jt.rotation.values.push_back(glm::angleAxis(angle, Vec3(0.0f, 0.0f, 1.0f)));
  }
  jt.rotation.times = std::move(times);
  raw.tracks.push_back(std::move(jt));
  return raw;
}

TEST(ExtremeClips, DuplicateAndOutOfOrderKeyTimesAreRejectedNamingTheKey) {
  const auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  struct Case {
    std::vector<float> times;
    const char* field;
  } cases[] = {{{0.0f, 0.5f, 0.5f, 1.0f}, "rotation.times[2]"}, {{0.0f, 1.0f, 0.5f}, "rotation.times[2]"},
               {{1.0f, 0.0f}, "rotation.times[1]"}};
  for (const Case& c : cases) {
    const auto clip = anim::Clip::build(arm_clip(model->skeleton, c.times), model->skeleton, "raise.caf");
    ASSERT_FALSE(clip.ok()) << c.field;
    EXPECT_EQ(clip.status().code(), ErrorCode::kInvalidData);
    EXPECT_NE(clip.status().message().find("raise.caf"), std::string::npos) << clip.status().message();
    EXPECT_NE(clip.status().message().find(c.field), std::string::npos) << clip.status().message();
  }
}

// A one-key clip (at t = 0 and at a later time) bakes as a one-pose space
// and renders its single pose at every playback time.
TEST(ExtremeClips, ASingleKeyClipBakesAndRendersItsPoseAtEveryTime) {
  for (const float key_time : {0.0f, 0.75f}) {
    BakedModel m;
    m.model = content::make_mannequin().value();
    auto clip = anim::Clip::build(arm_clip(m.model.skeleton, {key_time}), m.model.skeleton, "raise");
    ASSERT_TRUE(clip.ok()) << clip.status().message();
    EXPECT_EQ(clip->duration(), key_time);
    m.model.clips = {std::move(*clip)};
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kClip;
    request.pose_space.clips = {"raise"};
    request.pose_space.samples = 0;
    request.pose_space.every_frame_30hz = true;
    JobSystem jobs(2);
    auto bake = character::bake_in_memory(m.model, request, jobs);
    ASSERT_TRUE(bake.ok()) << bake.status().message();
    m.bake = std::move(*bake);
    const std::vector<Affine3> at_zero = testing_support::clip_pose(m.model, "raise", 0.0);
    for (const double t : {0.4, 7.3}) {
      const std::vector<Affine3> bones = testing_support::clip_pose(m.model, "raise", t);
      for (std::size_t b = 0; b < bones.size(); ++b) {
        for (int r = 0; r < 3; ++r) ASSERT_EQ(bones[b].rows[r], at_zero[b].rows[r]) << "bone " << b;
      }
      rt::FrameStats stats;
      const rt::Scene scene = posed_scene(m, bones, &stats);
      EXPECT_EQ(stats.escaped_triangles, 0u) << "the one pose is the whole pose space";
      rt::CameraDesc desc;
      desc.eye = Vec3(1.0f, 1.4f, 3.0f);
      desc.target = Vec3(0.0f, 1.0f, 0.0f);
      expect_correct_image(render_and_compare(scene, desc, 48, 48), "single key", 300);
    }
  }
}

// --- skin weights ---------------------------------------------------------------

TEST(ExtremeWeights, WeightsSummingToHalfOrTwoAreRenormalisedWithAWarning) {
  const character::Model original = content::make_mannequin().value();
  character::Model odd = original;
  odd.source = "odd.glb";
  // Halve some rows, double others: exact in binary floating point, so the
  // renormalised rows must equal the original's renormalised rows bit for bit.
  for (std::size_t v = 0; v < odd.mesh.weights.size(); ++v) {
    for (float& w : odd.mesh.weights[v]) w *= (v % 2 == 0) ? 0.5f : 2.0f;
  }
  ASSERT_TRUE(character::normalize_skin_weights(odd).ok());
  ASSERT_EQ(odd.warnings.size(), 1u);
  EXPECT_NE(odd.warnings[0].find("odd.glb"), std::string::npos) << odd.warnings[0];
  EXPECT_NE(odd.warnings[0].find("weights[0]"), std::string::npos) << odd.warnings[0];
  EXPECT_NE(odd.warnings[0].find("0.5"), std::string::npos) << odd.warnings[0];
  EXPECT_NE(odd.warnings[0].find(std::to_string(odd.mesh.vertex_count()) + " of " +
                                 std::to_string(odd.mesh.vertex_count())),
            std::string::npos)
      << odd.warnings[0];

  character::Model reference = original;
  ASSERT_TRUE(character::normalize_skin_weights(reference).ok());
  EXPECT_TRUE(reference.warnings.empty()) << "the mannequin's own weights sum to 1: " << reference.warnings[0];
  EXPECT_EQ(odd.mesh.weights, reference.mesh.weights);

  // End to end: bake the renormalised model, render a walk pose, compare with
  // brute force over the ORIGINAL model's skinned triangles.
  BakedModel m;
  m.model = std::move(odd);
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {"walk"};
  request.pose_space.samples = 0;
  JobSystem jobs(2);
  auto bake = character::bake_in_memory(m.model, request, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  m.bake = std::move(*bake);
  const std::vector<Affine3> bones = testing_support::clip_pose(m.model, "walk", 0.35);
  const rt::Scene scene = posed_scene(m, bones);
  rt::Scene truth;
  const std::uint32_t ch = truth.add_character(original.mesh, m.bake.fuzzy.view()).value();
  ASSERT_TRUE(truth.set_bones(truth.add_instance(ch).value(), bones).ok());
  ASSERT_TRUE(truth.prepare_frame(rt::FrameOptions{}, jobs).ok());
  const auto ours = testing_support::world_triangles(scene);
  const auto ref = testing_support::world_triangles(truth);
  ASSERT_EQ(ours.size(), ref.size());
  for (std::size_t t = 0; t < ours.size(); ++t) {
    // The original weights are unit up to rounding: positions agree closely.
    for (const auto& [a, b] : {std::pair{ours[t].p0, ref[t].p0}, std::pair{ours[t].p1, ref[t].p1}}) {
      ASSERT_LT(glm::length(a - b), 1e-5f) << "triangle " << t;
    }
  }
  rt::CameraDesc desc;
  desc.eye = Vec3(-1.0f, 1.2f, 3.0f);
  desc.target = Vec3(0.0f, 0.9f, 0.0f);
  expect_correct_image(render_and_compare(scene, desc, 48, 48), "renormalised weights", 300);
}

TEST(ExtremeWeights, RoundingLevelSumsAreRenormalisedSilently) {
  SkinnedMesh mesh;
  mesh.positions = {Vec3(0.0f), Vec3(1.0f), Vec3(2.0f)};
  mesh.weights = {{0.5f, 0.5f}, {0.2f, 0.3f, 0.499f}, {1.0f}};
  std::vector<std::string> warnings;
  ASSERT_TRUE(character::normalize_skin_weights(mesh, "q.glb", warnings).ok());
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(mesh.weights[0][0], 0.5f) << "an exact row keeps its bits";
  double sum = 0.0;
  for (const float w : mesh.weights[1]) sum += static_cast<double>(w);
  EXPECT_NEAR(sum, 1.0, 1e-6);
}

TEST(ExtremeWeights, UnusableWeightsAreClearErrors) {
  struct Case {
    std::array<float, kMaxInfluences> row;
    const char* field;
  } cases[] = {{{0.0f}, "weights[1]"},
               {{0.5f, -0.5f}, "weights[1][1]"},
               {{0.5f, std::numeric_limits<float>::quiet_NaN()}, "weights[1][1]"},
               {{std::numeric_limits<float>::infinity()}, "weights[1][0]"}};
  for (const Case& c : cases) {
    SkinnedMesh mesh;
    mesh.positions = {Vec3(0.0f), Vec3(1.0f)};
    mesh.weights = {{1.0f}, c.row};
    std::vector<std::string> warnings;
    const Status s = character::normalize_skin_weights(mesh, "bad.glb", warnings);
    ASSERT_FALSE(s.ok()) << c.field;
    EXPECT_EQ(s.code(), ErrorCode::kInvalidData);
    EXPECT_EQ(s.field(), c.field);
    EXPECT_NE(s.message().find("bad.glb"), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace sinew::extremes
