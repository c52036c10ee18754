#include "editor/bake/in_memory_bake.h"

#include <chrono>

#include "animation/pose.h"
#include "runtime/jobs/job_system.h"

namespace sinew::editor {
namespace {

Status append_skinning(const anim::Skeleton& skeleton, std::span<const anim::JointTransform> local,
                       const Affine3& instance, std::vector<Affine3>& model_scratch,
                       std::vector<Affine3>& out) {
  const std::size_t joints = skeleton.joint_count();
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

Expected<std::vector<Affine3>> pose_space_skinning(const ImportedModel& model,
                                                   const anim::PoseSpaceDesc& space,
                                                   std::span<const anim::JointLimit> limits) {
  std::vector<Affine3> out;
  std::vector<Affine3> model_scratch;
  const bool clip_space = space.mode == anim::PoseSpaceMode::kClips || space.mode == anim::PoseSpaceMode::kClip;
  if (clip_space && model.clips.empty()) {
    std::vector<anim::JointTransform> rest(model.skeleton.joint_count());
    SINEW_RETURN_IF_ERROR(anim::rest_pose(model.skeleton, rest));
    SINEW_RETURN_IF_ERROR(append_skinning(model.skeleton, rest, Affine3::identity(), model_scratch, out));
    return out;
  }
  SINEW_RETURN_IF_ERROR(anim::for_each_pose(
      space, model.skeleton, model.clips, limits, [&](std::span<const anim::JointTransform> local) {
        return append_skinning(model.skeleton, local, Affine3::identity(), model_scratch, out);
      }));
  return out;
}

Expected<std::vector<Affine3>> clip_skinning(const ImportedModel& model, const anim::Clip& clip,
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

Expected<InMemoryBake> bake_in_memory(const ImportedModel& model, const BakeRequest& request, JobSystem& jobs) {
  InMemoryBake bake;
  const auto start = std::chrono::steady_clock::now();
  SINEW_ASSIGN_OR_RETURN(std::vector<Affine3> samples,
                         pose_space_skinning(model, request.pose_space, request.limits));
  bake.pose_sampling_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  rt::FuzzyBakeInput input;
  input.mesh = &model.mesh;
  input.bone_count = static_cast<std::uint32_t>(model.skeleton.joint_count());
  input.bone_parents = model.skeleton.parents();
  input.samples = samples;
  SINEW_ASSIGN_OR_RETURN(bake.fuzzy, rt::bake_fuzzy_character(input, request.fuzzy, jobs));
  return bake;
}

}  // namespace sinew::editor
