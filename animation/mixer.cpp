#include "animation/mixer.h"

#include <cmath>
#include <string>

namespace sinew::anim {
namespace {

Status check_non_negative(std::string_view field, float v) {
  if (!std::isfinite(v) || v < 0.0f) {
    return invalid_argument(field, std::to_string(v), "must be finite and >= 0");
  }
  return Status{};
}

// Cal3D wraps with fmod; a zero-length clip would make that NaN, so it
// simply stays at time 0.
float wrap(float t, float duration) {
  if (duration <= 0.0f) return 0.0f;
  return std::fmod(t, duration);
}

}  // namespace

Status Mixer::check_clip(int clip) const {
  if (clip < 0 || static_cast<std::size_t>(clip) >= clips_.size()) {
    return invalid_argument("clip", std::to_string(clip),
                            "out of range [0, " + std::to_string(clips_.size()) + ")");
  }
  return Status{};
}

float Mixer::clip_duration(int clip) const {
  return clips_[static_cast<std::size_t>(clip)].duration();
}

Mixer::Cycle* Mixer::registered_cycle(int clip) {
  for (Cycle& c : cycles_) {
    if (c.clip == clip && c.registered) return &c;
  }
  return nullptr;
}

const Mixer::Cycle* Mixer::newest_cycle(int clip) const {
  for (auto it = cycles_.rbegin(); it != cycles_.rend(); ++it) {
    if (it->clip == clip) return &*it;
  }
  return nullptr;
}

const Mixer::Action* Mixer::newest_action(int clip) const {
  for (auto it = actions_.rbegin(); it != actions_.rend(); ++it) {
    if (it->clip == clip) return &*it;
  }
  return nullptr;
}

Status Mixer::blend_cycle(int clip, float weight, float delay) {
  SINEW_RETURN_IF_ERROR(check_clip(clip));
  SINEW_RETURN_IF_ERROR(check_non_negative("weight", weight));
  SINEW_RETURN_IF_ERROR(check_non_negative("delay", delay));

  Cycle* cycle = registered_cycle(clip);
  if (cycle == nullptr) {
    if (weight == 0.0f) return Status{};  // clearing an inactive cycle
    if (clips_[static_cast<std::size_t>(clip)].tracks().empty()) {
      return invalid_argument("clip", std::to_string(clip),
                              "has no tracks (Cal3D refuses to blend an empty animation)");
    }
    Cycle fresh;
    fresh.clip = clip;
    fresh.sync = sync_new_cycles_;
    cycles_.push_back(fresh);  // the newest is last (Cal3D's list front)
    cycle = &cycles_.back();
  } else if (weight == 0.0f) {
    // Cal3D forgets the cycle here but leaves it in the list, still in
    // sync, to fade out; a new blend_cycle then starts another instance.
    cycle->registered = false;
  }
  cycle->target_weight = weight;
  cycle->target_delay = delay;
  rebuild_layers();
  return Status{};
}

void Mixer::set_async(Cycle& cycle) const {
  if (!cycle.sync) return;
  // Keep the phase and playback rate it had on the global clock.
  if (duration_ == 0.0f) {
    cycle.time_factor = 1.0f;
    cycle.time = 0.0f;
  } else {
    cycle.time_factor = clip_duration(cycle.clip) / duration_;
    cycle.time = time_ * cycle.time_factor;
  }
  cycle.sync = false;
}

Status Mixer::clear_cycle(int clip, float delay) {
  SINEW_RETURN_IF_ERROR(check_clip(clip));
  SINEW_RETURN_IF_ERROR(check_non_negative("delay", delay));
  Cycle* cycle = registered_cycle(clip);
  if (cycle == nullptr) return Status{};
  cycle->registered = false;
  set_async(*cycle);
  cycle->target_weight = 0.0f;
  cycle->target_delay = delay;
  rebuild_layers();
  return Status{};
}

Status Mixer::execute_action(int clip, float fade_in, float fade_out, float weight, bool lock) {
  SINEW_RETURN_IF_ERROR(check_clip(clip));
  SINEW_RETURN_IF_ERROR(check_non_negative("fade_in", fade_in));
  SINEW_RETURN_IF_ERROR(check_non_negative("fade_out", fade_out));
  SINEW_RETURN_IF_ERROR(check_non_negative("weight", weight));
  Action action;
  action.clip = clip;
  action.fade_in = fade_in;
  action.fade_out = fade_out;
  action.weight_target = weight;
  action.lock = lock;
  actions_.push_back(action);  // the newest is last (Cal3D's list front)
  rebuild_layers();
  return Status{};
}

Status Mixer::remove_action(int clip) {
  SINEW_RETURN_IF_ERROR(check_clip(clip));
  for (std::size_t i = actions_.size(); i-- > 0;) {
    if (actions_[i].clip == clip) {
      actions_.erase(actions_.begin() + static_cast<std::ptrdiff_t>(i));
      rebuild_layers();
      return Status{};
    }
  }
  return make_error(ErrorCode::kNotFound, "", "clip", std::to_string(clip),
                    "no action of this clip is running");
}

// CalAnimationCycle::update: returns false once the cycle has faded out.
bool Mixer::update_cycle(Cycle& cycle, float dt) const {
  if (cycle.target_delay <= dt) {
    cycle.weight = cycle.target_weight;
    cycle.target_delay = 0.0f;
    if (cycle.weight == 0.0f) return false;
  } else {
    // Moving the remaining gap by dt / remaining each step is a linear ramp.
    const float factor = dt / cycle.target_delay;
    cycle.weight = (1.0f - factor) * cycle.weight + factor * cycle.target_weight;
    cycle.target_delay -= dt;
  }
  if (!cycle.sync) {
    cycle.time += dt * cycle.time_factor;
    const float d = clip_duration(cycle.clip);
    if (cycle.time >= d) cycle.time = wrap(cycle.time, d);
  }
  return true;
}

// CalAnimationAction::update: returns false once the action has ended.
bool Mixer::update_action(Action& a, float dt) const {
  const float d = clip_duration(a.clip);
  if (a.phase != Phase::kStopped) a.time += dt;
  if (a.phase == Phase::kIn) {
    if (a.time < a.fade_in) {
      a.weight = a.time / a.fade_in * a.weight_target;  // fade_in > time >= 0
    } else {
      a.phase = Phase::kSteady;
      a.weight = a.weight_target;
    }
  }
  if (a.phase == Phase::kSteady) {
    if (!a.lock && a.time >= d - a.fade_out) {
      a.phase = Phase::kOut;
    } else if (a.lock && a.time > d) {
      a.phase = Phase::kStopped;
      a.time = d;  // hold the last frame
    }
  }
  if (a.phase == Phase::kOut) {
    if (a.time < d) {
      // Here d - fade_out <= time < d, so fade_out > 0.
      a.weight = (d - a.time) / a.fade_out * a.weight_target;
    } else {
      a.weight = 0.0f;
      return false;
    }
  }
  return true;
}

void Mixer::update(float dt) {
  if (!std::isfinite(dt) || dt < 0.0f) dt = 0.0f;

  // The global clock advances with last update's period (Cal3D order).
  if (duration_ == 0.0f) {
    time_ = 0.0f;
  } else {
    time_ += dt * time_factor_;
    if (time_ >= duration_ || time_ < 0.0f) time_ = wrap(time_, duration_);
    if (time_ < 0.0f) time_ += duration_;  // fmod keeps the sign: a clock running backwards
  }

  // Newest first, as Cal3D walks its lists.
  for (std::size_t i = actions_.size(); i-- > 0;) {
    if (!update_action(actions_[i], dt)) {
      actions_.erase(actions_.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }

  float accumulated_weight = 0.0f;
  float accumulated_duration = 0.0f;
  for (std::size_t i = cycles_.size(); i-- > 0;) {
    Cycle& c = cycles_[i];
    if (!update_cycle(c, dt)) {
      cycles_.erase(cycles_.begin() + static_cast<std::ptrdiff_t>(i));
      continue;
    }
    if (c.sync) {
      accumulated_weight += c.weight;
      accumulated_duration += c.weight * clip_duration(c.clip);
    }
  }
  duration_ = accumulated_weight > 0.0f ? accumulated_duration / accumulated_weight : 0.0f;
  rebuild_layers();
}

Status Mixer::set_time_factor(float factor) {
  if (!std::isfinite(factor)) return invalid_argument("time_factor", std::to_string(factor), "must be finite");
  time_factor_ = factor;
  return Status{};
}

void Mixer::set_synchronized_cycles(bool on) {
  sync_new_cycles_ = on;
  if (on) return;
  for (Cycle& c : cycles_) set_async(c);
  rebuild_layers();
}

float Mixer::sampled_time(const Cycle& cycle) const {
  if (!cycle.sync) return cycle.time;
  if (duration_ == 0.0f) return 0.0f;
  // Same operation order as CalMixer::updateSkeleton.
  return time_ * clip_duration(cycle.clip) / duration_;
}

void Mixer::rebuild_layers() {
  layers_.clear();
  for (auto a = actions_.rbegin(); a != actions_.rend(); ++a) {
    layers_.push_back({a->clip, a->time, a->weight, true});
  }
  for (auto c = cycles_.rbegin(); c != cycles_.rend(); ++c) {
    layers_.push_back({c->clip, sampled_time(*c), c->weight, false});
  }
}

float Mixer::cycle_weight(int clip) const {
  const Cycle* c = newest_cycle(clip);
  return c != nullptr ? c->weight : 0.0f;
}

float Mixer::cycle_time(int clip) const {
  const Cycle* c = newest_cycle(clip);
  return c != nullptr ? sampled_time(*c) : 0.0f;
}

bool Mixer::cycle_active(int clip) const { return newest_cycle(clip) != nullptr; }

bool Mixer::cycle_synchronized(int clip) const {
  const Cycle* c = newest_cycle(clip);
  return c != nullptr && c->sync;
}

float Mixer::action_weight(int clip) const {
  const Action* a = newest_action(clip);
  return a != nullptr ? a->weight : 0.0f;
}

float Mixer::action_time(int clip) const {
  const Action* a = newest_action(clip);
  return a != nullptr ? a->time : 0.0f;
}

bool Mixer::action_active(int clip) const { return newest_action(clip) != nullptr; }

}  // namespace sinew::anim
