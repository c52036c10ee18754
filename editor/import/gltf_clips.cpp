// Clips (gltf_clips.h): samplers' inputs and outputs decoded and checked,
// and copied into tracks, folded where the joint's rest pose was.
#include "editor/import/gltf_clips.h"

#include <string>
#include <utility>

#include "editor/import/gltf_accessors.h"

namespace sinew::editor::gltf_detail {
namespace {

template <typename T, typename F>
void fill_track(anim::Track<T>& track, anim::Interpolation interp, const AccessorData& in,
                const AccessorData& out, F&& convert) {
  track.interpolation = interp;
  track.times.resize(in.count);
  for (std::size_t k = 0; k < in.count; ++k) track.times[k] = static_cast<float>(in.at(k, 0));
  track.values.resize(out.count);
  const std::size_t per = interp == anim::Interpolation::kCubicSpline ? 3 : 1;
  for (std::size_t k = 0; k < out.count; ++k) {
    // In cubic splines the tangents (slots 0 and 2 of each triple) are
    // derivatives: the folded transform's translation must not apply to them.
    const bool tangent = per == 3 && (k % 3) != 1;
    track.values[k] = convert(out, k, tangent);
  }
}

}  // namespace

Expected<std::vector<anim::Clip>> build_clips(const Ctx& c, const SkeletonPlan& plan,
                                              const anim::Skeleton& skeleton,
                                              const std::vector<int>& raw_to_sorted) {
  std::vector<anim::Clip> clips;
  if (c.model.animations.size() > c.limits.max_clips) {
    return c.limit("animations", c.model.animations.size(), "clips", c.limits.max_clips, "--max-clips");
  }
  std::size_t keys = 0;
  for (std::size_t a = 0; a < c.model.animations.size(); ++a) {
    const tinygltf::Animation& anim_in = c.model.animations[a];
    const std::string afield = idx("animations", a);
    anim::RawClip raw;
    raw.name = anim_in.name.empty() ? "animation_" + std::to_string(a) : anim_in.name;
    std::vector<int> track_of(plan.joint_nodes.size(), -1);
    for (std::size_t ch = 0; ch < anim_in.channels.size(); ++ch) {
      const tinygltf::AnimationChannel& channel = anim_in.channels[ch];
      const std::string cfield = idx(afield + ".channels", ch);
      const std::string& path = channel.target_path;
      if (path == "weights") continue;  // morph targets: not supported, ignored
      if (path != "translation" && path != "rotation" && path != "scale") {
        return c.error(ErrorCode::kInvalidData, cfield + ".target.path", path,
                       "unknown animation path");
      }
      const int node = channel.target_node;
      if (node < -1 || node >= static_cast<int>(c.model.nodes.size())) {
        return c.error(ErrorCode::kOutOfBounds, cfield + ".target.node", std::to_string(node),
                       "no such node");
      }
      if (node == -1) continue;  // targets an extension's object
      const int raw_joint = plan.node_to_raw[static_cast<std::size_t>(node)];
      if (raw_joint == -1) continue;  // non-joint nodes are not animated
      if (channel.sampler < 0 ||
          static_cast<std::size_t>(channel.sampler) >= anim_in.samplers.size()) {
        return c.error(ErrorCode::kOutOfBounds, cfield + ".sampler",
                       std::to_string(channel.sampler), "no such sampler");
      }
      const tinygltf::AnimationSampler& sampler =
          anim_in.samplers[static_cast<std::size_t>(channel.sampler)];
      const std::string sfield = idx(afield + ".samplers", static_cast<std::size_t>(channel.sampler));
      anim::Interpolation interp;
      if (sampler.interpolation.empty() || sampler.interpolation == "LINEAR") {
        interp = anim::Interpolation::kLinear;
      } else if (sampler.interpolation == "STEP") {
        interp = anim::Interpolation::kStep;
      } else if (sampler.interpolation == "CUBICSPLINE") {
        interp = anim::Interpolation::kCubicSpline;
      } else {
        return c.error(ErrorCode::kInvalidData, sfield + ".interpolation", sampler.interpolation,
                       "unknown interpolation");
      }
      SINEW_ASSIGN_OR_RETURN(AccessorData in,
                             read_accessor(c, sampler.input, sfield + ".input",
                                           {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}));
      // Channels may share samplers: every use counts, as every use is copied.
      keys += in.count;
      if (keys > c.limits.max_keys) {
        return c.limit(sfield + ".input", keys, "animation keys in all", c.limits.max_keys, "--max-keys");
      }
      const bool rot = path == "rotation";
      SINEW_ASSIGN_OR_RETURN(
          AccessorData out,
          rot ? read_accessor(c, sampler.output, sfield + ".output", {TINYGLTF_TYPE_VEC4},
                              {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                               TINYGLTF_COMPONENT_TYPE_SHORT,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT})
              : read_accessor(c, sampler.output, sfield + ".output", {TINYGLTF_TYPE_VEC3},
                              {TINYGLTF_COMPONENT_TYPE_FLOAT}));
      const std::size_t per = interp == anim::Interpolation::kCubicSpline ? 3 : 1;
      if (in.count == 0 || out.count != in.count * per) {
        return c.error(ErrorCode::kInvalidData, sfield + ".output", std::to_string(out.count),
                       "expected " + std::to_string(in.count * per) + " values for " +
                           std::to_string(in.count) + " keys");
      }
      int& t = track_of[static_cast<std::size_t>(raw_joint)];
      if (t == -1) {
        t = static_cast<int>(raw.tracks.size());
        anim::JointTracks jt;
        jt.joint = raw_to_sorted[static_cast<std::size_t>(raw_joint)];
        raw.tracks.push_back(std::move(jt));
      }
      anim::JointTracks& jt = raw.tracks[static_cast<std::size_t>(t)];
      const bool fold = plan.fold_needed[static_cast<std::size_t>(raw_joint)];
      const Trs& p = plan.fold[static_cast<std::size_t>(raw_joint)];
      const bool dup = (path == "translation" && !jt.translation.empty()) ||
                       (rot && !jt.rotation.empty()) || (path == "scale" && !jt.scale.empty());
      if (dup) {
        return c.error(ErrorCode::kDuplicate, cfield + ".target", path,
                       "two channels animate the same property of one node");
      }
      if (path == "translation") {
        fill_track(jt.translation, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool tangent) {
                     DVec3 v(d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) v = tangent ? p.s.x * (p.r * v) : fold_translation(p, v);
                     return Vec3(v);
                   });
      } else if (rot) {
        fill_track(jt.rotation, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool) {
                     DQuat q(d.at(k, 3), d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) q = fold_rotation(p, q);  // linear, so tangents too
                     return Quat(q);
                   });
      } else {
        fill_track(jt.scale, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool) {
                     DVec3 v(d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) v = fold_scale(p, v);
                     return Vec3(v);
                   });
      }
    }
    SINEW_ASSIGN_OR_RETURN(anim::Clip clip, anim::Clip::build(std::move(raw), skeleton, c.file));
    clips.push_back(std::move(clip));
  }
  return clips;
}

}  // namespace sinew::editor::gltf_detail
