#include "editor/gui/pose_player.h"

#include <algorithm>
#include <string>

#include "animation/pose.h"

namespace sinew::editor::gui {

PosePlayer::PosePlayer(const character::Model& model) : model_(&model), mixer_(model.clips) {
  const std::size_t joints = model.skeleton.joint_count();
  local_.resize(joints);
  model_pose_.resize(joints);
  skin_.resize(joints);
  caches_.resize(model.clips.size());
  for (std::size_t k = 0; k < model.clips.size(); ++k) caches_[k].reset(model.clips[k]);
  for (std::size_t k = 0; k < model.clips.size(); ++k) {
    if (!model.clips[k].tracks().empty()) {
      clip_a_ = static_cast<int>(k);
      break;
    }
  }
  (void)rebuild();  // cannot fail: clip_a_ has tracks
}

Status PosePlayer::set_cycles(int clip_a, int clip_b, float blend) {
  const int count = static_cast<int>(model_->clips.size());
  if (clip_a < -1 || clip_a >= count) return invalid_argument("clip", std::to_string(clip_a), "no such clip");
  if (clip_b < -1 || clip_b >= count) return invalid_argument("clip", std::to_string(clip_b), "no such clip");
  clip_a_ = clip_a;
  clip_b_ = clip_b;
  blend_ = std::clamp(blend, 0.0f, 1.0f);
  return rebuild();
}

Status PosePlayer::seek(double seconds) {
  time_ = std::max(0.0, seconds);
  return rebuild();
}

Status PosePlayer::rebuild() {
  mixer_ = anim::Mixer(model_->clips);
  const bool two = clip_b_ >= 0 && clip_b_ != clip_a_;
  const float weight_a = two ? 1.0f - blend_ : 1.0f;
  const float weight_b = two ? blend_ : 0.0f;
  if (clip_a_ >= 0 && weight_a > 0.0f) SINEW_RETURN_IF_ERROR(mixer_.blend_cycle(clip_a_, weight_a, 0.0f));
  if (two && weight_b > 0.0f) SINEW_RETURN_IF_ERROR(mixer_.blend_cycle(clip_b_, weight_b, 0.0f));
  // The first update fixes the weights and the sync period; the second
  // moves the shared clock to the requested time.
  mixer_.update(0.0f);
  mixer_.update(static_cast<float>(time_));
  return Status{};
}

void PosePlayer::advance(double seconds) {
  time_ += seconds;
  mixer_.update(static_cast<float>(seconds));
}

Status PosePlayer::trigger_action(int clip) {
  return mixer_.execute_action(clip, 0.2f, 0.2f);
}

double PosePlayer::duration() const {
  double d = 0.0;
  for (int c : {clip_a_, clip_b_}) {
    if (c >= 0) d = std::max(d, static_cast<double>(model_->clips[static_cast<std::size_t>(c)].duration()));
  }
  return d > 0.0 ? d : 1.0;
}

const std::vector<Affine3>& PosePlayer::skinning() {
  const anim::Skeleton& skeleton = model_->skeleton;
  const Status evaluated = anim::evaluate_layers(skeleton, model_->clips, mixer_.layers(), caches_, local_, &scratch_);
  if (!evaluated.ok()) (void)anim::rest_pose(skeleton, local_);
  (void)anim::local_to_model(skeleton, local_, model_pose_);
  (void)anim::skinning_matrices(skeleton, model_pose_, Affine3::identity(), skin_);
  return skin_;
}

}  // namespace sinew::editor::gui
