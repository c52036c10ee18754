// Clip: keyframed tracks for some joints of one skeleton (Cal3D's
// CalCoreAnimation, glTF's animation). Immutable and shared by instances;
// the per-instance playback state is a SamplingCache.
//
// Time is seconds on the file's own timeline (docs/ANIMATION.md, "Skeleton
// and clips"): before a track's first key it holds the first value, after
// its last key the last.
// A looping clip of duration D (its last key time) plays t mod D.
//
// Key times (the one rule for every source): a track's times must be finite,
// >= 0 and strictly increasing. Duplicate or out-of-order times are
// REJECTED by Clip::build (kInvalidData naming "...times[k]"), never sorted:
// sorting would silently pick an order between equal-time keys and hide a
// broken exporter. glTF requires strictly increasing times, so its files
// pass unchanged; the Cal3D importer keeps the last of equal-time keys
// itself before building (Cal3D's own upper-bound sampling does the same),
// and hands anything else to this rule. A single key holds its value at
// every time; a clip whose keys are all at 0 has duration 0 and loops to 0.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animation/joint_transform.h"
#include "runtime/core/expected.h"

namespace sinew::anim {

class Skeleton;

enum class Interpolation : std::uint8_t {
  kStep,         // hold each key until the next
  kLinear,       // lerp; slerp (shortest path) for rotations
  kCubicSpline,  // glTF CUBICSPLINE: Hermite with per-key in/out tangents
};

std::string_view interpolation_name(Interpolation i);

// One channel of one joint. For kCubicSpline, `values` holds three entries
// per key in glTF order: in-tangent, value, out-tangent.
template <typename T>
struct Track {
  Interpolation interpolation = Interpolation::kLinear;
  std::vector<float> times;  // strictly increasing after Clip::build
  std::vector<T> values;

  bool empty() const { return times.empty(); }
};

struct JointTracks {
  int joint = 0;  // index in the skeleton
  Track<Vec3> translation;
  Track<Quat> rotation;
  Track<Vec3> scale;
};

struct RawClip {
  std::string name;
  std::vector<JointTracks> tracks;  // joints without tracks keep their rest pose
};

class Clip {
 public:
  Clip() = default;

  // Validates `raw` against `skeleton`: joint indices in range and unique,
  // times finite, non-negative and strictly increasing (duplicate or
  // unordered key times are rejected, naming the key), values finite,
  // value counts matching key counts (3x for cubic splines), rotations of
  // non-zero length (normalised here).
  static Expected<Clip> build(RawClip raw, const Skeleton& skeleton, std::string_view source);

  const std::string& name() const { return name_; }
  float duration() const { return duration_; }  // the last key time over all tracks
  std::span<const JointTracks> tracks() const { return tracks_; }
  std::size_t channel_count() const { return tracks_.size() * 3; }

 private:
  std::string name_;
  float duration_ = 0.0f;
  std::vector<JointTracks> tracks_;
};

// Per instance and clip: the last key interval found per channel, so
// sequential playback finds the next interval in O(1) instead of a search.
struct SamplingCache {
  std::vector<std::uint32_t> last_key;  // channel_count() entries
  void reset(const Clip& clip) { last_key.assign(clip.channel_count(), 0); }
};

// The clip's local time for a playback time: t mod duration when looping
// (a zero-duration clip always gives 0), t clamped to >= 0 otherwise.
float clip_time(const Clip& clip, double playback_seconds, bool loop);

// Overwrites the local transforms of the joints the clip animates, at clip
// time `time`; other entries of `local` are left as they are (callers
// initialise them with the rest pose). `local` has joint_count() entries;
// `cache` is reset automatically when it does not match the clip.
void sample_clip(const Clip& clip, float time, SamplingCache& cache, std::span<JointTransform> local);

// Interpolation primitives, exposed for tests and the mixer.
Quat slerp_shortest(const Quat& a, const Quat& b, float t);

}  // namespace sinew::anim
