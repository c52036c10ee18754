#include "animation/clip.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "animation/skeleton.h"

namespace sinew::anim {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const Quat& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

template <typename T>
Status validate_track(Track<T>& track, std::string_view source, const std::string& field) {
  const std::size_t keys = track.times.size();
  const std::size_t per_key = track.interpolation == Interpolation::kCubicSpline ? 3 : 1;
  if (track.values.size() != keys * per_key) {
    return make_error(ErrorCode::kInvalidData, source, field + ".values",
                      std::to_string(track.values.size()),
                      "expected " + std::to_string(keys * per_key) + " values for " +
                          std::to_string(keys) + " keys (" +
                          std::string(interpolation_name(track.interpolation)) + ")");
  }
  for (std::size_t k = 0; k < keys; ++k) {
    const float t = track.times[k];
    const std::string key_field = field + ".times[" + std::to_string(k) + "]";
    if (!std::isfinite(t) || t < 0.0f) {
      return make_error(ErrorCode::kInvalidData, source, key_field, std::to_string(t),
                        "key times must be finite and non-negative");
    }
    if (k > 0 && !(t > track.times[k - 1])) {
      return make_error(ErrorCode::kInvalidData, source, key_field, std::to_string(t),
                        "key times must increase strictly (previous key at " +
                            std::to_string(track.times[k - 1]) + ")");
    }
  }
  for (std::size_t v = 0; v < track.values.size(); ++v) {
    if (!finite(track.values[v])) {
      return make_error(ErrorCode::kInvalidData, source, field + ".values[" + std::to_string(v) + "]",
                        "nan/inf", "non-finite key value");
    }
  }
  if constexpr (std::is_same_v<T, Quat>) {
    for (std::size_t v = 0; v < track.values.size(); ++v) {
      // Tangents of a cubic spline may be zero; the key values may not.
      const bool is_value = per_key == 1 || v % 3 == 1;
      // In double: the squares of finite float components (up to 3.4e38)
      // overflow float, not double, and tiny ones do not underflow.
      const Quat& q = track.values[v];
      const double x = static_cast<double>(q.x), y = static_cast<double>(q.y), z = static_cast<double>(q.z),
                   w = static_cast<double>(q.w);
      const double len = std::sqrt(x * x + y * y + z * z + w * w);
      if (is_value && len < 1e-6) {
        return make_error(ErrorCode::kInvalidData, source, field + ".values[" + std::to_string(v) + "]",
                          "0", "zero-length rotation quaternion");
      }
      if (is_value) track.values[v] = unit_rotation(q);
    }
  }
  return {};
}

// The key interval [k, k+1] holding t, for times[0] < t < times.back().
// Sequential playback moves forward by at most a key or two per frame, so
// walk from the cached interval; jump backwards (a loop wrap) by binary search.
std::uint32_t find_interval(const std::vector<float>& times, float t, std::uint32_t& hint) {
  const auto last_interval = static_cast<std::uint32_t>(times.size() - 2);
  std::uint32_t k = std::min(hint, last_interval);
  if (times[k] <= t) {
    while (k < last_interval && times[k + 1] <= t) ++k;
  } else {
    const auto it = std::upper_bound(times.begin(), times.end(), t);
    k = static_cast<std::uint32_t>(it - times.begin()) - 1;
  }
  hint = k;
  return k;
}

Vec3 lerp(const Vec3& a, const Vec3& b, float u) { return a + (b - a) * u; }

template <typename T>
T hermite(const T& v0, const T& out0, const T& in1, const T& v1, float s, float dt) {
  const float s2 = s * s;
  const float s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * v0 + (s3 - 2 * s2 + s) * dt * out0 + (-2 * s3 + 3 * s2) * v1 +
         (s3 - s2) * dt * in1;
}

// An interpolated cubic-spline rotation made unit length. Keys are unit, but
// the spline between them may pass through zero (two keys of opposite sign
// with zero tangents reach (0, 0, 0, 0) halfway) or overflow (huge finite
// tangents), and normalising that gives NaN. Then the nearer key stands in:
// the spline has no direction there to keep. Lengths are taken in double,
// as for the keys, so large finite components do not overflow.
Quat unit_or_nearer_key(const Quat& r, const Quat& key0, const Quat& key1, float u) {
  const double x = static_cast<double>(r.x), y = static_cast<double>(r.y), z = static_cast<double>(r.z),
               w = static_cast<double>(r.w);
  const double len = std::sqrt(x * x + y * y + z * z + w * w);
  if (!(len > 1e-6) || !std::isfinite(len)) return u < 0.5f ? key0 : key1;
  return Quat(static_cast<float>(w / len), static_cast<float>(x / len), static_cast<float>(y / len),
              static_cast<float>(z / len));
}

// Finite keys far apart (or huge tangents) can overflow float between them;
// the nearer key stands in for an infinite or NaN result.
Vec3 finite_or_nearer_key(const Vec3& r, const Vec3& key0, const Vec3& key1, float u) {
  if (finite(r)) return r;
  return u < 0.5f ? key0 : key1;
}

template <typename T>
T sample_track(const Track<T>& track, float t, std::uint32_t& hint) {
  const std::size_t n = track.times.size();
  const bool cubic = track.interpolation == Interpolation::kCubicSpline;
  auto value = [&](std::size_t k) -> const T& { return track.values[cubic ? 3 * k + 1 : k]; };
  if (n == 1 || t <= track.times.front()) return value(0);
  if (t >= track.times.back()) return value(n - 1);
  const std::uint32_t k = find_interval(track.times, t, hint);
  const float t0 = track.times[k];
  const float t1 = track.times[k + 1];
  const float u = (t - t0) / (t1 - t0);
  switch (track.interpolation) {
    case Interpolation::kStep:
      return value(k);
    case Interpolation::kLinear:
      if constexpr (std::is_same_v<T, Quat>) {
        return slerp_shortest(value(k), value(k + 1), u);
      } else {
        return finite_or_nearer_key(lerp(value(k), value(k + 1), u), value(k), value(k + 1), u);
      }
    case Interpolation::kCubicSpline: {
      const T out0 = track.values[3 * k + 2];
      const T in1 = track.values[3 * (k + 1)];
      const T r = hermite(value(k), out0, in1, value(k + 1), u, t1 - t0);
      if constexpr (std::is_same_v<T, Quat>) {
        return unit_or_nearer_key(r, value(k), value(k + 1), u);  // the glTF spec: normalise after evaluation
      } else {
        return finite_or_nearer_key(r, value(k), value(k + 1), u);
      }
    }
  }
  return value(k);
}

}  // namespace

std::string_view interpolation_name(Interpolation i) {
  switch (i) {
    case Interpolation::kStep: return "STEP";
    case Interpolation::kLinear: return "LINEAR";
    case Interpolation::kCubicSpline: return "CUBICSPLINE";
  }
  return "unknown";
}

Quat slerp_shortest(const Quat& a, const Quat& b_in, float t) {
  Quat b = b_in;
  float cos_theta = glm::dot(a, b);
  if (cos_theta < 0.0f) {
    b = -b;
    cos_theta = -cos_theta;
  }
  if (cos_theta > 0.9995f) {
    // Nearly parallel: sin(theta) ~ 0, normalised lerp is accurate.
    return glm::normalize(Quat(a.w + (b.w - a.w) * t, a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t,
                               a.z + (b.z - a.z) * t));
  }
  const float theta = std::acos(cos_theta);
  const float sin_theta = std::sin(theta);
  const float wa = std::sin((1.0f - t) * theta) / sin_theta;
  const float wb = std::sin(t * theta) / sin_theta;
  return Quat(wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z);
}

Expected<Clip> Clip::build(RawClip raw, const Skeleton& skeleton, std::string_view source) {
  const std::size_t joints = skeleton.joint_count();
  std::vector<bool> seen(joints, false);
  Clip clip;
  clip.name_ = std::move(raw.name);
  for (std::size_t i = 0; i < raw.tracks.size(); ++i) {
    JointTracks& jt = raw.tracks[i];
    const std::string field = "clip '" + clip.name_ + "'.tracks[" + std::to_string(i) + "]";
    if (jt.joint < 0 || static_cast<std::size_t>(jt.joint) >= joints) {
      return make_error(ErrorCode::kOutOfBounds, source, field + ".joint", std::to_string(jt.joint),
                        "not a joint of the skeleton (" + std::to_string(joints) + " joints)");
    }
    if (seen[static_cast<std::size_t>(jt.joint)]) {
      return make_error(ErrorCode::kDuplicate, source, field + ".joint", std::to_string(jt.joint),
                        "two track sets for one joint");
    }
    seen[static_cast<std::size_t>(jt.joint)] = true;
    SINEW_RETURN_IF_ERROR(validate_track(jt.translation, source, field + ".translation"));
    SINEW_RETURN_IF_ERROR(validate_track(jt.rotation, source, field + ".rotation"));
    SINEW_RETURN_IF_ERROR(validate_track(jt.scale, source, field + ".scale"));
    for (const auto* times : {&jt.translation.times, &jt.rotation.times, &jt.scale.times}) {
      if (!times->empty()) clip.duration_ = std::max(clip.duration_, times->back());
    }
  }
  // Joint order makes sampling walk the pose array forwards.
  std::sort(raw.tracks.begin(), raw.tracks.end(),
            [](const JointTracks& a, const JointTracks& b) { return a.joint < b.joint; });
  clip.tracks_ = std::move(raw.tracks);
  return clip;
}

float clip_time(const Clip& clip, double playback_seconds, bool loop) {
  const double d = clip.duration();
  if (!loop) return static_cast<float>(std::max(0.0, playback_seconds));
  if (d <= 0.0) return 0.0f;
  double t = std::fmod(playback_seconds, d);
  if (t < 0.0) t += d;
  return static_cast<float>(t);
}

void sample_clip(const Clip& clip, float time, SamplingCache& cache, std::span<JointTransform> local) {
  if (cache.last_key.size() != clip.channel_count()) cache.reset(clip);
  std::uint32_t* hint = cache.last_key.data();
  for (const JointTracks& jt : clip.tracks()) {
    if (static_cast<std::size_t>(jt.joint) >= local.size()) break;  // built for another skeleton
    JointTransform& out = local[static_cast<std::size_t>(jt.joint)];
    if (!jt.translation.empty()) out.translation = sample_track(jt.translation, time, hint[0]);
    if (!jt.rotation.empty()) out.rotation = sample_track(jt.rotation, time, hint[1]);
    if (!jt.scale.empty()) out.scale = sample_track(jt.scale, time, hint[2]);
    hint += 3;
  }
}

}  // namespace sinew::anim
