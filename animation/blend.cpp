#include "animation/blend.h"

#include <cmath>
#include <string>

namespace sinew::anim {
namespace {

std::string to_text(float v) { return std::to_string(v); }

std::string layer_field(std::size_t i, const char* member) {
  return "layers[" + std::to_string(i) + "]." + member;
}

// Cal3D's CalVector::blend: v += d * (target - v), per component.
Vec3 vec_blend(const Vec3& v, const Vec3& target, float d) { return v + d * (target - v); }

// CalBone::blendState for one joint (0.11.0 form: no ramp, scale or
// replacement attenuation; the later fork's extra parameters default to
// values that reduce to this).
void blend_state(BlendScratch& s, std::size_t j, float weight, const JointTransform& sample) {
  float& accumulated = s.group_weight[j];
  JointTransform& state = s.group[j];
  if (accumulated == 0.0f) {
    // First state of the group: copied as is. A zero weight leaves the
    // accumulator at 0, so the next layer overwrites it, as in Cal3D.
    state = sample;
    accumulated = weight;
    return;
  }
  const float factor = weight / (accumulated + weight);
  state.translation = vec_blend(state.translation, sample.translation, factor);
  state.rotation = cal3d_quat_blend(state.rotation, sample.rotation, factor);
  state.scale = vec_blend(state.scale, sample.scale, factor);
  accumulated += weight;
}

// CalSkeleton::lockState over all joints: folds the group into the locked
// state with whatever weight the earlier groups left over.
void lock_state(BlendScratch& s, std::span<JointTransform> locked) {
  for (std::size_t j = 0; j < locked.size(); ++j) {
    float& group = s.group_weight[j];
    float& weight = s.weight[j];
    if (group > 1.0f - weight) group = 1.0f - weight;
    if (group > 0.0f) {
      if (weight == 0.0f) {
        locked[j] = s.group[j];
        weight = group;
      } else {
        const float factor = group / (weight + group);
        JointTransform& out = locked[j];
        out.translation = vec_blend(out.translation, s.group[j].translation, factor);
        out.rotation = cal3d_quat_blend(out.rotation, s.group[j].rotation, factor);
        out.scale = vec_blend(out.scale, s.group[j].scale, factor);
        weight += group;
      }
      group = 0.0f;
    }
  }
}

Status validate(const Skeleton& skeleton, std::span<const Clip> clips,
                std::span<const BlendLayer> layers, std::span<SamplingCache> caches,
                std::span<JointTransform> out_local) {
  const std::size_t joints = skeleton.joint_count();
  if (out_local.size() != joints) {
    return invalid_argument("out_local.size()", std::to_string(out_local.size()),
                            "must equal the skeleton's joint count " + std::to_string(joints));
  }
  if (caches.size() != clips.size()) {
    return invalid_argument("caches.size()", std::to_string(caches.size()),
                            "must equal the clip count " + std::to_string(clips.size()));
  }
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const BlendLayer& l = layers[i];
    if (l.clip < 0 || static_cast<std::size_t>(l.clip) >= clips.size()) {
      return invalid_argument(layer_field(i, "clip"), std::to_string(l.clip),
                              "out of range [0, " + std::to_string(clips.size()) + ")");
    }
    if (!std::isfinite(l.weight) || l.weight < 0.0f) {
      return invalid_argument(layer_field(i, "weight"), to_text(l.weight),
                              "must be finite and >= 0");
    }
    if (!std::isfinite(l.time)) {
      return invalid_argument(layer_field(i, "time"), to_text(l.time), "must be finite");
    }
    for (const JointTracks& jt : clips[static_cast<std::size_t>(l.clip)].tracks()) {
      if (jt.joint < 0 || static_cast<std::size_t>(jt.joint) >= joints) {
        return invalid_argument(layer_field(i, "clip"), std::to_string(l.clip),
                                "animates joint " + std::to_string(jt.joint) +
                                    " but the skeleton has " + std::to_string(joints));
      }
    }
  }
  return Status{};
}

}  // namespace

Quat cal3d_quat_blend(const Quat& a, const Quat& b, float d) {
  // Same operation order as CalQuaternion::blend (x, y, z, w), so float
  // rounding matches the library we are compared against.
  float norm = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  bool flip = false;
  if (norm < 0.0f) {
    norm = -norm;
    flip = true;
  }
  float inv_d = 0.0f;
  if (1.0f - norm < 0.000001f) {
    inv_d = 1.0f - d;
  } else {
    // Cal3D calls the double versions of acos and sin.
    const float theta = static_cast<float>(std::acos(static_cast<double>(norm)));
    const float s = static_cast<float>(1.0 / std::sin(static_cast<double>(theta)));
    inv_d = static_cast<float>(std::sin(static_cast<double>((1.0f - d) * theta)) *
                               static_cast<double>(s));
    d = static_cast<float>(std::sin(static_cast<double>(d * theta)) * static_cast<double>(s));
  }
  if (flip) d = -d;
  Quat r;
  r.x = inv_d * a.x + d * b.x;
  r.y = inv_d * a.y + d * b.y;
  r.z = inv_d * a.z + d * b.z;
  r.w = inv_d * a.w + d * b.w;
  return r;
}

Status evaluate_layers(const Skeleton& skeleton, std::span<const Clip> clips,
                       std::span<const BlendLayer> layers, std::span<SamplingCache> caches,
                       std::span<JointTransform> out_local, BlendScratch* scratch) {
  SINEW_RETURN_IF_ERROR(validate(skeleton, clips, layers, caches, out_local));

  BlendScratch temporary;
  BlendScratch& s = scratch != nullptr ? *scratch : temporary;
  const std::size_t joints = skeleton.joint_count();
  const std::span<const JointTransform> rest = skeleton.rest_pose();
  s.sampled.resize(joints);
  s.group.resize(joints);
  s.group_weight.assign(joints, 0.0f);  // CalSkeleton::clearState
  s.weight.assign(joints, 0.0f);

  // out_local plays the role of each bone's locked (relative) state.
  bool group_open = false;
  bool group_is_action = false;
  for (const BlendLayer& layer : layers) {
    if (group_open && layer.action != group_is_action) lock_state(s, out_local);
    group_open = true;
    group_is_action = layer.action;

    const auto c = static_cast<std::size_t>(layer.clip);
    const Clip& clip = clips[c];
    // Channels a joint's tracks leave empty read as the rest pose (Cal3D
    // tracks always carry both translation and rotation).
    for (const JointTracks& jt : clip.tracks()) {
      s.sampled[static_cast<std::size_t>(jt.joint)] = rest[static_cast<std::size_t>(jt.joint)];
    }
    sample_clip(clip, layer.time, caches[c], s.sampled);
    for (const JointTracks& jt : clip.tracks()) {
      const auto j = static_cast<std::size_t>(jt.joint);
      blend_state(s, j, layer.weight, s.sampled[j]);
    }
  }
  if (group_open) lock_state(s, out_local);

  // CalBone::calculateState: untouched bones fall back to the core pose.
  for (std::size_t j = 0; j < joints; ++j) {
    if (s.weight[j] == 0.0f) out_local[j] = rest[j];
  }
  return Status{};
}

}  // namespace sinew::anim
