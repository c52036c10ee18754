#include "animation/pose.h"

#include <string>

namespace sinew::anim {
namespace {

Status check_size(std::string_view what, std::size_t got, std::size_t want) {
  if (got == want) return {};
  return invalid_argument(what, std::to_string(got),
                          "span size must equal the joint count " + std::to_string(want));
}

}  // namespace

Status rest_pose(const Skeleton& skeleton, std::span<JointTransform> local) {
  SINEW_RETURN_IF_ERROR(check_size("local", local.size(), skeleton.joint_count()));
  std::copy(skeleton.rest_pose().begin(), skeleton.rest_pose().end(), local.begin());
  return {};
}

Status local_to_model(const Skeleton& skeleton, std::span<const JointTransform> local,
                      std::span<Affine3> model) {
  const std::size_t n = skeleton.joint_count();
  SINEW_RETURN_IF_ERROR(check_size("local", local.size(), n));
  SINEW_RETURN_IF_ERROR(check_size("model", model.size(), n));
  const auto parents = skeleton.parents();
  for (std::size_t j = 0; j < n; ++j) {
    const Affine3 l = local[j].to_affine();
    const int p = parents[j];
    model[j] = p == kNoParent ? l : model[static_cast<std::size_t>(p)] * l;
  }
  return {};
}

Status skinning_matrices(const Skeleton& skeleton, std::span<const Affine3> model,
                         const Affine3& instance, std::span<Affine3> skin) {
  const std::size_t n = skeleton.joint_count();
  SINEW_RETURN_IF_ERROR(check_size("model", model.size(), n));
  SINEW_RETURN_IF_ERROR(check_size("skin", skin.size(), n));
  const auto inverse_bind = skeleton.inverse_bind();
  for (std::size_t j = 0; j < n; ++j) skin[j] = instance * (model[j] * inverse_bind[j]);
  return {};
}

}  // namespace sinew::anim
