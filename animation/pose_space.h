// Pose-space samplers for the fuzzy-box bake (paper section 3.3, Table 1):
// the bake skins the mesh in every sampled pose and bounds each vertex in
// each bone's frame, so the pose space chosen here trades posing freedom
// for tighter fuzzy boxes.
//
// All modes are deterministic: the random modes draw from std::mt19937_64
// (whose output sequence the standard fixes) with our own integer-to-float
// conversion, so a seed gives the same poses with any standard library.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animation/clip.h"
#include "animation/joint_limits.h"
#include "animation/joint_transform.h"
#include "runtime/core/expected.h"

namespace sinew::anim {

class Skeleton;

enum class PoseSpaceMode : std::uint8_t {
  kArbitrary,  // every joint: a rotation uniform on SO(3)
  kLimits,     // every joint: a rotation uniform (Haar measure) inside its limit;
               // free joints as kArbitrary
  kClips,      // the key times of the named clips (all clips when none named)
  kClip,       // the key times of exactly one named clip
};

std::string_view pose_space_mode_name(PoseSpaceMode mode);  // "arbitrary", "limits", "clips", "clip"
Expected<PoseSpaceMode> parse_pose_space_mode(std::string_view name);

// A generous ceiling on poses per bake: keeps a typo in a config from
// queueing days of work.
inline constexpr int kMaxPoseSamples = 10'000'000;

// A clip sampled every 1/30 s at every time found (kClips/kClip with
// every_frame_30hz and samples = 0) may last this long: 18,000 poses, each
// skinned over every vertex and bone by the bake. A longer clip is refused
// naming it, its length and this limit; `samples` N bounds the work
// instead (N poses chosen evenly over its times), whatever its length.
inline constexpr double kMaxClipSecondsEveryFrame = 600.0;

struct PoseSpaceDesc {
  PoseSpaceMode mode = PoseSpaceMode::kArbitrary;
  std::vector<std::string> clips;  // kClips: names (empty = every clip); kClip: one name
  // kArbitrary/kLimits: the number of poses (> 0; Table 1 uses 1000 and 245).
  // kClips/kClip: 0 = every time found; otherwise at most this many, chosen
  // evenly over the sorted times (first and last kept).
  int samples = 1000;
  std::uint64_t seed = 1;  // kArbitrary/kLimits only
  // kClips/kClip: also sample every 1/30 s over each clip's duration.
  bool every_frame_30hz = false;
};

// Poses are local transforms, joint_count() entries each. Random modes set
// rotation = rest * delta with translation and scale at rest; clip modes
// start from the rest pose and sample the clip over it (so each clip is
// sampled alone). `limits` is needed by kLimits only (one per joint; an
// empty span there is kInvalidArgument: nothing to be "within").
// Errors: kInvalidArgument (bad samples, limits size, kClip without exactly
// one name), kNotFound naming an unknown clip, kLimitExceeded naming a clip
// too long to sample every 1/30 s, or whatever `visit` returns, which stops
// the walk.
Status for_each_pose(const PoseSpaceDesc& desc, const Skeleton& skeleton, std::span<const Clip> clips,
                     std::span<const JointLimit> limits,
                     const std::function<Status(std::span<const JointTransform>)>& visit);

// Every pose in memory; for_each_pose keeps a bake's memory bounded.
Expected<std::vector<std::vector<JointTransform>>> sample_pose_space(const PoseSpaceDesc& desc,
                                                                     const Skeleton& skeleton,
                                                                     std::span<const Clip> clips,
                                                                     std::span<const JointLimit> limits);

// Sampling primitives, exposed for tests.

// Deterministic uniform numbers from a 64-bit generator output: the top 24
// (float) or 53 (double) bits scaled into [0, 1).
inline float unit_float(std::uint64_t bits) {
  return static_cast<float>(bits >> 40) * 0x1.0p-24f;
}
inline double unit_double(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

// Shoemake's uniform random rotation from three uniforms in [0, 1).
Quat uniform_rotation(double u1, double u2, double u3);

// The distinct clip times kClips/kClip visit for one clip, sorted.
std::vector<float> clip_sample_times(const Clip& clip, bool every_frame_30hz);

}  // namespace sinew::anim
