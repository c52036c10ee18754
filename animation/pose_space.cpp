#include "animation/pose_space.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <random>
#include <string>

#include "animation/pose.h"
#include "animation/skeleton.h"

namespace sinew::anim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
// Rejection loops give up after this many proposals and take a fallback
// draw: keeps a pathological limit (a needle-thin ellipse) from stalling the
// bake while staying deterministic.
constexpr int kMaxRejections = 4096;

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double next() { return unit_double(engine_()); }
  double in(double lo, double hi) { return lo + (hi - lo) * next(); }

 private:
  std::mt19937_64 engine_;  // its sequence is fixed by the standard
};

// Middle Tait-Bryan angle under the Haar measure: density |cos b| on
// [lo, hi] (first and last angles are uniform). Rejection against the
// largest |cos| on the interval.
double sample_middle_angle(Random& rng, double lo, double hi) {
  if (!(hi > lo)) return lo;
  double bound = std::max(std::abs(std::cos(lo)), std::abs(std::cos(hi)));
  for (double peak : {-kPi, 0.0, kPi}) {
    if (lo <= peak && peak <= hi) bound = 1.0;
  }
  if (!(bound > 0.0)) return rng.in(lo, hi);
  double b = lo;
  for (int i = 0; i < kMaxRejections; ++i) {
    b = rng.in(lo, hi);
    if (rng.next() * bound <= std::abs(std::cos(b))) return b;
  }
  return b;
}

Quat sample_euler(Random& rng, const EulerLimit& limit) {
  // Positions in the order: the middle axis is the one whose angle carries
  // the cos weight.
  int axes[3] = {0, 1, 2};
  switch (limit.order) {
    case RotationOrder::kXYZ:
      axes[0] = 0;
      axes[1] = 1;
      axes[2] = 2;
      break;
    case RotationOrder::kXZY:
      axes[0] = 0;
      axes[1] = 2;
      axes[2] = 1;
      break;
    case RotationOrder::kYXZ:
      axes[0] = 1;
      axes[1] = 0;
      axes[2] = 2;
      break;
    case RotationOrder::kYZX:
      axes[0] = 1;
      axes[1] = 2;
      axes[2] = 0;
      break;
    case RotationOrder::kZXY:
      axes[0] = 2;
      axes[1] = 0;
      axes[2] = 1;
      break;
    case RotationOrder::kZYX:
      axes[0] = 2;
      axes[1] = 1;
      axes[2] = 0;
      break;
  }
  Vec3 angles(0.0f);
  const auto lo = [&](int p) { return static_cast<double>(limit.min[axes[p]]); };
  const auto hi = [&](int p) { return static_cast<double>(limit.max[axes[p]]); };
  // Drawn in a fixed order (first, middle, last) for reproducibility.
  const double a = rng.in(lo(0), hi(0));
  const double b = sample_middle_angle(rng, lo(1), hi(1));
  const double c = rng.in(lo(2), hi(2));
  // Rounding must not step outside a range edge.
  angles[axes[0]] = std::clamp(static_cast<float>(a), limit.min[axes[0]], limit.max[axes[0]]);
  angles[axes[1]] = std::clamp(static_cast<float>(b), limit.min[axes[1]], limit.max[axes[1]]);
  angles[axes[2]] = std::clamp(static_cast<float>(c), limit.min[axes[2]], limit.max[axes[2]]);
  return compose_euler(limit.order, angles);
}

// Haar measure in swing-twist coordinates is the area measure of the
// swung twist axis on the sphere times a uniform twist angle: swing angle
// phi has density sin(phi), its direction is uniform, and the ellipse is
// enforced by rejection.
Quat sample_swing_twist(Random& rng, const SwingTwistLimit& limit) {
  const double twist = rng.in(static_cast<double>(limit.twist_min), static_cast<double>(limit.twist_max));
  const double m1 = static_cast<double>(limit.swing_max_1);
  const double m2 = static_cast<double>(limit.swing_max_2);
  Vec2 swing(0.0f);
  if (m1 > 0.0 && m2 > 0.0) {
    const double cos_max = std::cos(std::max(m1, m2));
    double phi = 0.0, psi = 0.0;
    for (int i = 0; i < kMaxRejections; ++i) {
      phi = std::acos(std::clamp(rng.in(cos_max, 1.0), -1.0, 1.0));
      psi = rng.in(0.0, kTwoPi);
      const double e1 = phi * std::cos(psi) / m1, e2 = phi * std::sin(psi) / m2;
      if (e1 * e1 + e2 * e2 <= 1.0) break;
      if (i + 1 == kMaxRejections) phi = 0.0;  // fallback: no swing, always allowed
    }
    swing = Vec2(static_cast<float>(phi * std::cos(psi)), static_cast<float>(phi * std::sin(psi)));
  } else if (m1 > 0.0 || m2 > 0.0) {
    // A zero-width ellipse is an arc: arc length is uniform in the angle.
    const double m = std::max(m1, m2);
    const float phi = static_cast<float>(rng.in(-m, m));
    swing = m1 > 0.0 ? Vec2(phi, 0.0f) : Vec2(0.0f, phi);
  }
  const float t = std::clamp(static_cast<float>(twist), limit.twist_min, limit.twist_max);
  return compose_swing_twist(limit.twist_axis, swing, t);
}

std::vector<std::size_t> subsample(std::size_t n, int samples) {
  std::vector<std::size_t> idx;
  if (samples <= 0 || static_cast<std::size_t>(samples) >= n) {
    idx.resize(n);
    for (std::size_t i = 0; i < n; ++i) idx[i] = i;
    return idx;
  }
  const auto k = static_cast<std::size_t>(samples);
  if (k == 1) return {0};
  // Evenly spaced, first and last kept; integer arithmetic so every
  // platform picks the same indices.
  for (std::size_t i = 0; i < k; ++i) idx.push_back((i * (n - 1) + (k - 1) / 2) / (k - 1));
  return idx;
}

}  // namespace

std::string_view pose_space_mode_name(PoseSpaceMode mode) {
  switch (mode) {
    case PoseSpaceMode::kArbitrary: return "arbitrary";
    case PoseSpaceMode::kLimits: return "limits";
    case PoseSpaceMode::kClips: return "clips";
    case PoseSpaceMode::kClip: return "clip";
  }
  return "unknown";
}

Expected<PoseSpaceMode> parse_pose_space_mode(std::string_view name) {
  for (PoseSpaceMode m :
       {PoseSpaceMode::kArbitrary, PoseSpaceMode::kLimits, PoseSpaceMode::kClips, PoseSpaceMode::kClip}) {
    if (pose_space_mode_name(m) == name) return m;
  }
  return invalid_argument("pose_space.mode", name, "expected arbitrary, limits, clips or clip");
}

Quat uniform_rotation(double u1, double u2, double u3) {
  // Shoemake, "Uniform random rotations" (Graphics Gems III): a uniform
  // point on S^3 from two circles with radii sqrt(1 - u1) and sqrt(u1).
  const double r1 = std::sqrt(1.0 - u1), r2 = std::sqrt(u1);
  const double t1 = kTwoPi * u2, t2 = kTwoPi * u3;
  return Quat(static_cast<float>(r2 * std::cos(t2)), static_cast<float>(r1 * std::sin(t1)),
              static_cast<float>(r1 * std::cos(t1)), static_cast<float>(r2 * std::sin(t2)));
}

std::vector<float> clip_sample_times(const Clip& clip, bool every_frame_30hz) {
  std::vector<float> times;
  for (const JointTracks& jt : clip.tracks()) {
    times.insert(times.end(), jt.translation.times.begin(), jt.translation.times.end());
    times.insert(times.end(), jt.rotation.times.begin(), jt.rotation.times.end());
    times.insert(times.end(), jt.scale.times.begin(), jt.scale.times.end());
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  if (every_frame_30hz) {
    const double duration = static_cast<double>(clip.duration());
    // for_each_pose rejects clips this long first; the clamp keeps a direct
    // caller from allocating without bound.
    const auto frames = static_cast<long long>(
        std::min(std::floor(duration * 30.0 + 1e-6), static_cast<double>(kMaxPoseSamples)));
    std::vector<float> grid;
    for (long long k = 0; k <= frames; ++k) {
      const auto t = static_cast<float>(static_cast<double>(k) / 30.0);
      // A frame time that (nearly) coincides with a key adds no new pose.
      const auto it = std::lower_bound(times.begin(), times.end(), t);
      const bool near_next = it != times.end() && *it - t < 1e-5f;
      const bool near_prev = it != times.begin() && t - *(it - 1) < 1e-5f;
      if (!near_next && !near_prev) grid.push_back(t);
    }
    times.insert(times.end(), grid.begin(), grid.end());
    std::sort(times.begin(), times.end());
  }
  return times;
}

Status for_each_pose(const PoseSpaceDesc& desc, const Skeleton& skeleton, std::span<const Clip> clips,
                     std::span<const JointLimit> limits,
                     const std::function<Status(std::span<const JointTransform>)>& visit) {
  const std::size_t n = skeleton.joint_count();
  std::vector<JointTransform> rest(n);
  SINEW_RETURN_IF_ERROR(rest_pose(skeleton, rest));
  if (desc.samples < 0) {
    return invalid_argument("pose_space.samples", std::to_string(desc.samples), "must not be negative");
  }
  if (desc.samples > kMaxPoseSamples) {
    return make_error(ErrorCode::kLimitExceeded, "", "pose_space.samples", std::to_string(desc.samples),
                      "more than " + std::to_string(kMaxPoseSamples) + " poses");
  }
  std::vector<JointTransform> pose = rest;

  if (desc.mode == PoseSpaceMode::kArbitrary || desc.mode == PoseSpaceMode::kLimits) {
    if (desc.samples == 0) {
      return invalid_argument("pose_space.samples", "0", "random pose spaces need a sample count");
    }
    if (desc.mode == PoseSpaceMode::kLimits) {
      if (limits.empty()) {
        return invalid_argument("pose_space.limits", "none",
                                "the limits pose space needs joint limits (load content/limits/<model>.json) "
                                "or use the arbitrary pose space");
      }
      if (limits.size() != n) {
        return invalid_argument("pose_space.limits", std::to_string(limits.size()),
                                "expected one limit per joint (" + std::to_string(n) + ")");
      }
      SINEW_RETURN_IF_ERROR(validate_joint_limits(limits, "pose_space.limits"));
    }
    Random rng(desc.seed);
    for (int s = 0; s < desc.samples; ++s) {
      for (std::size_t j = 0; j < n; ++j) {
        const JointLimit* limit = desc.mode == PoseSpaceMode::kLimits ? &limits[j] : nullptr;
        Quat delta;
        if (limit != nullptr && limit->kind == LimitKind::kEuler) {
          delta = sample_euler(rng, limit->euler);
        } else if (limit != nullptr && limit->kind == LimitKind::kSwingTwist) {
          delta = sample_swing_twist(rng, limit->swing_twist);
        } else {
          const double u1 = rng.next(), u2 = rng.next(), u3 = rng.next();
          delta = uniform_rotation(u1, u2, u3);
        }
        pose[j].rotation = glm::normalize(rest[j].rotation) * delta;
      }
      SINEW_RETURN_IF_ERROR(visit(pose));
    }
    return {};
  }

  // Clip modes: resolve names first so a typo fails before any work.
  std::vector<const Clip*> chosen;
  if (desc.mode == PoseSpaceMode::kClip) {
    if (desc.clips.size() != 1) {
      return invalid_argument("pose_space.clips", std::to_string(desc.clips.size()) + " names",
                              "the clip pose space takes exactly one clip name");
    }
  } else if (desc.mode != PoseSpaceMode::kClips) {
    return invalid_argument("pose_space.mode", std::to_string(static_cast<int>(desc.mode)), "unknown mode");
  }
  if (desc.clips.empty()) {
    for (const Clip& c : clips) chosen.push_back(&c);
  } else {
    for (std::size_t i = 0; i < desc.clips.size(); ++i) {
      const std::string& name = desc.clips[i];
      const Clip* found = nullptr;
      for (const Clip& c : clips) {
        if (c.name() == name) {
          found = &c;
          break;
        }
      }
      if (found == nullptr) {
        return make_error(ErrorCode::kNotFound, "", "pose_space.clips[" + std::to_string(i) + "]", name,
                          "no clip of that name");
      }
      // Naming a clip twice would only repeat its poses.
      if (std::find(chosen.begin(), chosen.end(), found) == chosen.end()) chosen.push_back(found);
    }
  }
  if (chosen.empty()) {
    return invalid_argument("pose_space.clips", "none", "no clips to sample");
  }
  struct Sample {
    const Clip* clip;
    float time;
  };
  std::vector<Sample> all;
  for (const Clip* c : chosen) {
    const double seconds = static_cast<double>(c->duration());
    const double limit = desc.samples == 0 ? kMaxClipSecondsEveryFrame : kMaxPoseSamples / 30.0;
    if (desc.every_frame_30hz && seconds > limit) {
      char text[160];
      std::snprintf(text, sizeof text, "lasts %.6g s: sampling every 1/30 s takes clips of up to %.6g s (%s)",
                    seconds, limit,
                    desc.samples == 0 ? "anim::kMaxClipSecondsEveryFrame; or sample N poses of it"
                                      : "anim::kMaxPoseSamples at 30 Hz");
      return make_error(ErrorCode::kLimitExceeded, "", "pose_space.clips", printable(c->name(), 60), text);
    }
    for (float t : clip_sample_times(*c, desc.every_frame_30hz)) all.push_back({c, t});
  }
  SamplingCache cache;
  const Clip* cached_for = nullptr;
  for (std::size_t i : subsample(all.size(), desc.samples)) {
    const Sample& s = all[i];
    if (s.clip != cached_for) {
      cache.reset(*s.clip);
      cached_for = s.clip;
    }
    // Each clip is sampled alone over the rest pose.
    std::copy(rest.begin(), rest.end(), pose.begin());
    sample_clip(*s.clip, s.time, cache, pose);
    SINEW_RETURN_IF_ERROR(visit(pose));
  }
  return {};
}

Expected<std::vector<std::vector<JointTransform>>> sample_pose_space(const PoseSpaceDesc& desc,
                                                                     const Skeleton& skeleton,
                                                                     std::span<const Clip> clips,
                                                                     std::span<const JointLimit> limits) {
  std::vector<std::vector<JointTransform>> poses;
  SINEW_RETURN_IF_ERROR(for_each_pose(desc, skeleton, clips, limits, [&](std::span<const JointTransform> p) {
    poses.emplace_back(p.begin(), p.end());
    return Status{};
  }));
  return poses;
}

}  // namespace sinew::anim
