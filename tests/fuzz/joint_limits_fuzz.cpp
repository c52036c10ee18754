// libFuzzer target for joint-limit JSON (animation/joint_limits.h:
// parse_joint_limits) against a fixed skeleton, the procedural mannequin's.
//
// Each input is the JSON text. A finding: any sanitizer report, leak, trap,
// time-out or OOM; a refusal without an error code or message; or accepted
// limits that break the parser's promises: one entry per joint, ranges that
// pass validate_joint_limits, JSON written back by joint_limits_to_json that
// parses again, and clamp_rotation results that are unit quaternions
// accepted by is_within (checked for a few fixed rotations per joint).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "animation/joint_limits.h"
#include "animation/skeleton.h"
#include "content/mannequin/mannequin.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace sinew;

const anim::Skeleton& mannequin_skeleton() {
  static const anim::Skeleton skeleton = [] {
    auto model = content::make_mannequin();
    fuzz::require(model.ok());
    return model->skeleton;
  }();
  return skeleton;
}

// A few rotations in and out of typical ranges, including half-turns.
constexpr float kPi = 3.14159265358979f;
const Quat kProbes[] = {
    Quat(1.0f, 0.0f, 0.0f, 0.0f),
    glm::angleAxis(0.7f, glm::normalize(Vec3(1.0f, 2.0f, 3.0f))),
    glm::angleAxis(kPi, Vec3(0.0f, 1.0f, 0.0f)),
    glm::angleAxis(-2.5f, glm::normalize(Vec3(-1.0f, 0.5f, 0.0f))),
    glm::angleAxis(0.5f * kPi, Vec3(0.0f, 0.0f, 1.0f)) * glm::angleAxis(0.5f * kPi, Vec3(1.0f, 0.0f, 0.0f)),
};

void require_clamps_into_range(const anim::JointLimit& limit) {
  for (const Quat& probe : kProbes) {
    const Quat clamped = anim::clamp_rotation(limit, probe);
    const float length = glm::length(clamped);
    fuzz::require(std::isfinite(length) && std::fabs(length - 1.0f) < 1e-3f);
    fuzz::require(anim::is_within(limit, clamped, 1e-3f));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  const anim::Skeleton& skeleton = mannequin_skeleton();
  auto limits = anim::parse_joint_limits(json, skeleton, "fuzz.json");
  if (!limits.ok()) {
    fuzz::require_clear_error(limits.status());
    return 0;
  }
  fuzz::require(limits->size() == skeleton.joint_count());
  fuzz::require(anim::validate_joint_limits(*limits, "fuzz.json").ok());
  fuzz::require(anim::parse_joint_limits(anim::joint_limits_to_json(*limits, skeleton), skeleton,
                                         "written.json")
                    .ok());
  for (const anim::JointLimit& limit : *limits) require_clamps_into_range(limit);
  return 0;
}
