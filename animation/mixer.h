// Mixer: one character instance's animation scheduling with Cal3D's
// semantics (CalMixer, CalAnimationCycle, CalAnimationAction of Cal3D
// 0.11.0), the Mixer::update(dt) step of docs/DESIGN.md section 3.
//
// Ownership: the mixer holds per-instance state only (active cycles and
// actions, their weights, fades and times, the global sync time). It keeps
// a non-owning span of the shared, immutable clips for their durations; the
// clips must outlive it. It never samples: update() only schedules and
// layers() hands the result to evaluate_layers() (blend.h), which is how
// Cal3D splits updateAnimation from updateSkeleton (STYLE.md item 4).
// Units: seconds and Cal3D relative weights.
//
// Semantics reproduced from Cal3D (mixer.cpp, animation_cycle.cpp,
// animation_action.cpp):
//  * Cycles loop. blend_cycle moves a cycle's weight linearly to `weight`
//    over `delay` seconds (creating it with weight 0 if it is not active);
//    reaching weight 0 removes it. blend_cycle(c, 0, d) forgets the cycle
//    at once, so a later blend_cycle(c, w, d) starts a second instance while
//    the first still fades out (Cal3D's table vs list behaviour).
//  * Synchronised cycles (Cal3D's SYNC state, the default) share one global
//    time whose period is the weight-averaged duration of the sync cycles;
//    cycle c plays at global_time * duration(c) / global_duration, so walk
//    and run stay in phase. The global time advances by dt with the period
//    of the previous update and the period is recomputed afterwards, exactly
//    as in CalMixer::updateAnimation.
//  * clear_cycle makes the cycle ASYNC (it keeps its current phase and
//    playback rate, then runs on its own clock) and fades it to 0.
//  * Actions are one-shots in IN / STEADY / OUT / STOPPED phases: weight
//    ramps 0 -> weight over fade_in, holds, and from duration - fade_out
//    ramps back to 0 at the clip's end, where the action is removed. A
//    locked action skips OUT: once past its end it holds the last frame at
//    its weight until remove_action.
//  * Layers are emitted in Cal3D's evaluation order: actions (newest first),
//    then cycles (newest first). Actions take min(sum of weights, 1) of the
//    pose; cycles share the rest by normalised weights (see blend.h).
//  * The time factor (setTimeFactor) scales only the sync clock's step.
//  * Cal3D's blendCycle appends a closing key at the clip's duration when a
//    track ends earlier (loop closure). Our Clip's duration is its last key
//    time, so the Cal3D importer appends that key instead; nothing to do here.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "animation/blend.h"
#include "animation/clip.h"
#include "runtime/core/status.h"

namespace sinew::anim {

class Mixer {
 public:
  explicit Mixer(std::span<const Clip> clips) : clips_(clips) {}

  // Fades the looping clip's weight to `weight` over `delay` seconds.
  // A weight of 0 on an inactive clip does nothing. Errors
  // (kInvalidArgument): clip out of range or without tracks (Cal3D refuses
  // those too), weight or delay negative or not finite.
  Status blend_cycle(int clip, float weight, float delay);

  // Fades an active cycle out over `delay` seconds after desynchronising it;
  // an inactive clip is not an error. Errors: clip out of range, bad delay.
  Status clear_cycle(int clip, float delay);

  // Starts a one-shot of `clip` on top of everything (a clip may run as
  // several overlapping actions). Errors: clip out of range, negative or
  // non-finite fades or weight.
  Status execute_action(int clip, float fade_in, float fade_out, float weight = 1.0f,
                        bool lock = false);

  // Removes the newest action of `clip` at once (how a locked action ends).
  // Errors: kInvalidArgument for a bad index, kNotFound when no action of
  // that clip is running.
  Status remove_action(int clip);

  // Advances fades, phases and the global sync time by `dt` seconds. A
  // negative or non-finite dt is treated as 0 (Cal3D would run time
  // backwards into negative action weights).
  void update(float dt);

  // On (the default, Cal3D's behaviour): new cycles join the global sync
  // time. Off: new cycles run on their own clock from time 0, and cycles
  // now in sync are desynchronised keeping their phase. Turning it back on
  // affects cycles started afterwards only.
  void set_synchronized_cycles(bool on);
  bool synchronized_cycles() const { return sync_new_cycles_; }

  // Cal3D's CalMixer::setTimeFactor: update(dt) moves the global sync clock
  // by dt * factor, so synchronised cycles play faster, slower or (negative)
  // backwards, the clock wrapping into [0, period). Weight fades, actions
  // and desynchronised cycles keep real time, as in Cal3D. Default 1.
  // Errors (kInvalidArgument, nothing changed): a non-finite factor.
  Status set_time_factor(float factor);
  float time_factor() const { return time_factor_; }

  // The blend for the current state, in evaluation order (see blend.h).
  std::span<const BlendLayer> layers() const { return layers_; }

  // Cal3D's getAnimationTime / getAnimationDuration (the sync clock).
  float animation_time() const { return time_; }
  float animation_duration() const { return duration_; }

  // Introspection for tests and HUDs. Each refers to the newest instance of
  // the clip (a faded-out cycle and its replacement may coexist); 0 or
  // false when there is none.
  float cycle_weight(int clip) const;
  float cycle_time(int clip) const;  // the clip time it is sampled at
  bool cycle_active(int clip) const;
  bool cycle_synchronized(int clip) const;
  float action_weight(int clip) const;
  float action_time(int clip) const;
  bool action_active(int clip) const;
  std::size_t cycle_count() const { return cycles_.size(); }
  std::size_t action_count() const { return actions_.size(); }

 private:
  struct Cycle {
    int clip = 0;
    float weight = 0.0f;
    float target_weight = 0.0f;
    float target_delay = 0.0f;
    float time = 0.0f;         // own clock, used once async
    float time_factor = 1.0f;  // playback rate once async
    bool sync = true;
    bool registered = true;  // Cal3D's m_vectorAnimation[id] points at it
  };

  enum class Phase { kIn, kSteady, kOut, kStopped };

  struct Action {
    int clip = 0;
    Phase phase = Phase::kIn;
    float time = 0.0f;
    float weight = 0.0f;
    float fade_in = 0.0f;
    float fade_out = 0.0f;
    float weight_target = 1.0f;
    bool lock = false;
  };

  Status check_clip(int clip) const;
  float clip_duration(int clip) const;
  Cycle* registered_cycle(int clip);
  const Cycle* newest_cycle(int clip) const;
  const Action* newest_action(int clip) const;
  void set_async(Cycle& cycle) const;
  bool update_cycle(Cycle& cycle, float dt) const;
  bool update_action(Action& action, float dt) const;
  float sampled_time(const Cycle& cycle) const;
  void rebuild_layers();

  std::span<const Clip> clips_;
  // Both in start order, oldest first; walked newest first, which is Cal3D's
  // list order (push_front): it fixes the blend order and the float
  // summation order of the sync duration.
  std::vector<Cycle> cycles_;
  std::vector<Action> actions_;
  std::vector<BlendLayer> layers_;
  float time_ = 0.0f;      // Cal3D's m_animationTime
  float duration_ = 0.0f;  // Cal3D's m_animationDuration
  float time_factor_ = 1.0f;  // Cal3D's m_timeFactor
  bool sync_new_cycles_ = true;
};

}  // namespace sinew::anim
