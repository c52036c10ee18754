#include "character/bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

#include "animation/pose.h"
#include "character/renderable.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::character {
namespace {

Status append_skinning(const anim::Skeleton& skeleton, std::span<const anim::JointTransform> local,
                       const Affine3& instance, std::vector<Affine3>& model_scratch,
                       std::vector<Affine3>& out, std::size_t max_bytes = SIZE_MAX) {
  const std::size_t joints = skeleton.joint_count();
  const std::size_t max_matrices = max_bytes / sizeof(Affine3);
  if (joints > max_matrices || out.size() > max_matrices - joints) {
    const std::size_t samples = out.size() / std::max<std::size_t>(joints, 1);
    return make_error(ErrorCode::kLimitExceeded, "", "pose_space", "more than " + std::to_string(samples) + " samples",
                      "the pose samples of " + std::to_string(joints) + " joints would take more than " +
                          std::to_string(max_bytes >> 20) +
                          " MiB (the bake's memory bound); sample fewer poses or raise the bound");
  }
  model_scratch.resize(joints);
  SINEW_RETURN_IF_ERROR(anim::local_to_model(skeleton, local, model_scratch));
  const std::size_t first = out.size();
  out.resize(first + joints);
  return anim::skinning_matrices(skeleton, model_scratch, instance, std::span(out).subspan(first, joints));
}

}  // namespace

anim::PoseSpaceDesc default_pose_space() {
  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kClips;
  space.samples = 0;
  space.every_frame_30hz = true;
  return space;
}

Expected<std::vector<Affine3>> pose_space_skinning(const Model& model,
                                                   const anim::PoseSpaceDesc& space,
                                                   std::span<const anim::JointLimit> limits,
                                                   std::size_t max_bytes) {
  std::vector<Affine3> out;
  std::vector<Affine3> model_scratch;
  const bool clip_space = space.mode == anim::PoseSpaceMode::kClips || space.mode == anim::PoseSpaceMode::kClip;
  if (clip_space && model.clips.empty()) {
    std::vector<anim::JointTransform> rest(model.skeleton.joint_count());
    SINEW_RETURN_IF_ERROR(anim::rest_pose(model.skeleton, rest));
    SINEW_RETURN_IF_ERROR(append_skinning(model.skeleton, rest, Affine3::identity(), model_scratch, out, max_bytes));
    return out;
  }
  SINEW_RETURN_IF_ERROR(anim::for_each_pose(
      space, model.skeleton, model.clips, limits, [&](std::span<const anim::JointTransform> local) {
        return append_skinning(model.skeleton, local, Affine3::identity(), model_scratch, out, max_bytes);
      }));
  return out;
}

Expected<std::vector<Affine3>> rest_skinning(const Model& model, const Affine3& placement) {
  const std::size_t joints = model.skeleton.joint_count();
  std::vector<anim::JointTransform> local(joints);
  std::vector<Affine3> model_space(joints);
  std::vector<Affine3> skin(joints);
  SINEW_RETURN_IF_ERROR(anim::rest_pose(model.skeleton, local));
  SINEW_RETURN_IF_ERROR(anim::local_to_model(model.skeleton, local, model_space));
  SINEW_RETURN_IF_ERROR(anim::skinning_matrices(model.skeleton, model_space, placement, skin));
  return skin;
}

Expected<std::vector<Affine3>> clip_skinning(const Model& model, const anim::Clip& clip,
                                             double seconds, const Affine3& instance) {
  std::vector<anim::JointTransform> local(model.skeleton.joint_count());
  SINEW_RETURN_IF_ERROR(anim::rest_pose(model.skeleton, local));
  anim::SamplingCache cache;
  anim::sample_clip(clip, anim::clip_time(clip, seconds, /*loop=*/true), cache, local);
  std::vector<Affine3> out;
  std::vector<Affine3> model_scratch;
  SINEW_RETURN_IF_ERROR(append_skinning(model.skeleton, local, instance, model_scratch, out));
  return out;
}

Expected<InMemoryBake> bake_in_memory(const Model& model, const BakeRequest& request, JobSystem& jobs) {
  // A model the consumers of its pack would refuse is not baked.
  SINEW_RETURN_IF_ERROR(check_renderable(model, model.source));
  InMemoryBake bake;
  // The fuzzy bake holds an inverse per sample matrix beside its boxes.
  if (request.max_memory_bytes <= request.fuzzy.memory_budget_bytes) {
    return invalid_argument("max_memory_bytes", std::to_string(request.max_memory_bytes),
                            "must exceed the fuzzy bake's box budget (" +
                                std::to_string(request.fuzzy.memory_budget_bytes) + " bytes)");
  }
  const std::size_t sample_bound = (request.max_memory_bytes - request.fuzzy.memory_budget_bytes) / 2;
  const std::size_t joints = model.skeleton.joint_count();
  if (!request.poses.empty() && (joints == 0 || request.poses.size() % joints != 0)) {
    return invalid_argument("poses", std::to_string(request.poses.size()) + " matrices",
                            "not a whole number of poses of " + std::to_string(joints) + " joints");
  }
  const auto start = std::chrono::steady_clock::now();
  Expected<std::vector<Affine3>> sampled =
      request.poses.empty() ? pose_space_skinning(model, request.pose_space, request.limits, sample_bound)
                            : Expected<std::vector<Affine3>>(request.poses);
  if (!sampled.ok()) return sampled.status().with_file(model.source);
  const std::vector<Affine3>& samples = *sampled;
  bake.memory.pose_samples = samples.capacity() * sizeof(Affine3);
  bake.pose_sampling_ms = ms_since(start);
  rt::FuzzyBakeInput input;
  input.mesh = &model.mesh;
  input.bone_count = static_cast<std::uint32_t>(model.skeleton.joint_count());
  input.bone_parents = model.skeleton.parents();
  input.samples = samples;
  SINEW_ASSIGN_OR_RETURN(bake.fuzzy, rt::bake_fuzzy_character(input, request.fuzzy, jobs));
  bake.memory.fuzzy_peak = bake.fuzzy.stats.peak_bytes;
  return bake;
}

Expected<OutsideShare> triangles_outside(const Model& model, const rt::FuzzyCharacterView& fuzzy,
                                         std::span<const Affine3> poses, JobSystem& jobs) {
  const std::size_t joints = model.skeleton.joint_count();
  if (joints == 0 || poses.size() % joints != 0) {
    return invalid_argument("poses", std::to_string(poses.size()) + " matrices",
                            "not a whole number of poses of " + std::to_string(joints) + " joints");
  }
  OutsideShare share;
  const std::size_t triangles = model.mesh.triangle_count();
  if (triangles == 0 || poses.empty()) return share;
  rt::Scene scene;
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene.add_character(model.mesh, fuzzy));
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t instance, scene.add_instance(character));
  rt::FrameOptions options;
  options.normals = false;  // only the escape check is wanted
  double sum = 0.0;
  for (std::size_t p = 0; p < poses.size(); p += joints) {
    SINEW_RETURN_IF_ERROR(scene.set_bones(instance, poses.subspan(p, joints)));
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats stats, scene.prepare_frame(options, jobs));
    const double s = static_cast<double>(stats.escaped_triangles) / static_cast<double>(triangles);
    sum += s;
    share.max = std::max(share.max, s);
    ++share.poses;
  }
  share.mean = sum / static_cast<double>(share.poses);
  return share;
}

Expected<std::vector<Affine3>> clip_poses(const Model& model, const anim::Clip& clip, std::size_t max_poses) {
  const double duration = std::max(0.0, static_cast<double>(clip.duration()));
  const std::size_t every_frame = static_cast<std::size_t>(std::floor(duration * 30.0)) + 1;
  const std::size_t count = std::max<std::size_t>(1, std::min(every_frame, max_poses));
  std::vector<Affine3> out;
  for (std::size_t i = 0; i < count; ++i) {
    // Evenly over [0, duration]; clip_skinning loops, so the end is taken
    // just before it wraps.
    const double t = count == 1 ? 0.0 : duration * static_cast<double>(i) / static_cast<double>(count - 1);
    SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> pose,
                           clip_skinning(model, clip, std::min(t, std::nextafter(duration, 0.0))));
    out.insert(out.end(), pose.begin(), pose.end());
  }
  return out;
}

}  // namespace sinew::character
