// content/limits/cally.json, the joint limits the "limits" pose space and
// the paper benchmark use for Cally: they must admit every pose of Cally's
// own clips (a limit that clamps the model's animations would change them),
// and they must still limit something.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>

#include "animation/joint_limits.h"
#include "animation/pose_space.h"
#include "editor/import/cal3d_importer.h"

namespace sinew::editor {
namespace {

constexpr float kTolerance = 1e-3f;

std::string cally_cfg() { return std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg"; }
std::string cally_limits() { return std::string(SINEW_SOURCE_DIR) + "/content/limits/cally.json"; }

// Joints of `pose` outside their limit (rotation relative to the rest pose).
int violations(const anim::Skeleton& skeleton, const anim::JointLimits& limits,
               std::span<const anim::JointTransform> pose) {
  int outside = 0;
  const auto rest = skeleton.rest_pose();
  for (std::size_t j = 0; j < pose.size(); ++j) {
    const Quat delta = glm::conjugate(glm::normalize(rest[j].rotation)) * pose[j].rotation;
    if (!anim::is_within(limits[j], delta, kTolerance)) ++outside;
  }
  return outside;
}

TEST(CallyLimits, AdmitEveryPoseOfCallysClips) {
  auto model = import_cal3d(cally_cfg());
  ASSERT_TRUE(model.ok()) << model.status().message();
  auto limits = anim::load_joint_limits(cally_limits(), model->skeleton);
  ASSERT_TRUE(limits.ok()) << limits.status().message();
  ASSERT_TRUE(anim::validate_joint_limits(*limits, cally_limits()).ok());

  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kClips;
  space.samples = 0;  // every key time of every clip
  space.every_frame_30hz = true;
  int poses = 0, outside = 0;
  const Status walked = anim::for_each_pose(space, model->skeleton, model->clips, {},
                                            [&](std::span<const anim::JointTransform> pose) {
                                              ++poses;
                                              outside += violations(model->skeleton, *limits, pose);
                                              return Status{};
                                            });
  ASSERT_TRUE(walked.ok()) << walked.message();
  EXPECT_GT(poses, 500);
  EXPECT_EQ(outside, 0) << "joint poses outside content/limits/cally.json over " << poses << " clip poses";
}

TEST(CallyLimits, RejectMostArbitraryPoses) {
  auto model = import_cal3d(cally_cfg());
  ASSERT_TRUE(model.ok()) << model.status().message();
  auto limits = anim::load_joint_limits(cally_limits(), model->skeleton);
  ASSERT_TRUE(limits.ok()) << limits.status().message();
  int limited = 0;
  for (const anim::JointLimit& l : *limits) limited += l.kind != anim::LimitKind::kFree ? 1 : 0;
  EXPECT_GE(limited, 30) << "of " << limits->size() << " joints";

  // Uniform random rotations (our own Shoemake sampling from a fixed seed):
  // a limited joint admits only a small part of all rotations.
  std::mt19937_64 engine(2026);
  const auto u = [&] { return anim::unit_double(engine()); };
  int outside = 0, tried = 0;
  for (int i = 0; i < 200; ++i) {
    for (const anim::JointLimit& l : *limits) {
      if (l.kind == anim::LimitKind::kFree) continue;
      ++tried;
      if (!anim::is_within(l, anim::uniform_rotation(u(), u(), u()), kTolerance)) ++outside;
    }
  }
  EXPECT_GT(outside, tried * 9 / 10) << outside << " of " << tried;
}

}  // namespace
}  // namespace sinew::editor
