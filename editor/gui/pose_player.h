// PosePlayer: the clips panel's animation state. A Cal3D-style Mixer with up
// to two synchronised cycles (clip A at 1 - blend, clip B at blend) plus any
// triggered one-shot actions, posed into skinning matrices every frame.
//
// Scrubbing sets the playback time by rebuilding the mixer and advancing it
// from 0 (the mixer has no "seek"), which drops running actions.
#pragma once

#include <vector>

#include "animation/blend.h"
#include "animation/clip.h"
#include "animation/mixer.h"
#include "character/model.h"
#include "runtime/core/status.h"
#include "runtime/math/affine.h"

namespace sinew::editor::gui {

class PosePlayer {
 public:
  // Starts on the model's first clip with tracks (rest pose without one).
  explicit PosePlayer(const character::Model& model);

  // clip_a/clip_b: clip indices, -1 for none. blend in [0, 1].
  Status set_cycles(int clip_a, int clip_b, float blend);
  Status seek(double seconds);
  void advance(double seconds);  // when playing
  Status trigger_action(int clip);

  int clip_a() const { return clip_a_; }
  int clip_b() const { return clip_b_; }
  float blend() const { return blend_; }
  double time() const { return time_; }
  // The duration the time slider spans: the longer active cycle (1 s without).
  double duration() const;

  // Skinning matrices (bind pose -> world) of the current state.
  const std::vector<Affine3>& skinning();

 private:
  Status rebuild();

  const character::Model* model_;
  anim::Mixer mixer_;
  int clip_a_ = -1;
  int clip_b_ = -1;
  float blend_ = 0.0f;
  double time_ = 0.0;
  std::vector<anim::SamplingCache> caches_;
  anim::BlendScratch scratch_;
  std::vector<anim::JointTransform> local_;
  std::vector<Affine3> model_pose_;
  std::vector<Affine3> skin_;
};

}  // namespace sinew::editor::gui
