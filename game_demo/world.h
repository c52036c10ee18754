// The demo's game world: several characters on the arena floor, each its
// own instance with its own animation mixer. Non-player characters wander
// (idle pauses, walks, the odd run, occasional one-shot actions); one is the
// player's, driven by PlayerInput. Everything is deterministic: the same
// model, options and input sequence give bit-identical skinning matrices,
// whatever the thread count (the world steps on the calling thread).
//
// The world knows nothing about rendering: each step it hands on, per
// character, the bone (skinning) matrices bind pose -> world that the ray
// tracer consumes (rt::Scene::set_bones).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animation/mixer.h"
#include "character/model.h"
#include "runtime/core/expected.h"
#include "runtime/math/aabb.h"
#include "runtime/math/affine.h"

namespace sinew::demo {

// One step's player controls (keys, mouse, or the headless script).
struct PlayerInput {
  float forward = 0.0f;       // -1..1: W/S or up/down
  float right = 0.0f;         // -1..1: D/A or right/left
  bool run = false;           // Shift
  bool action = false;        // Space: starts a one-shot on this step (edge, not level)
  bool next_character = false;  // Tab: control passes to the next character (edge)
  float camera_yaw = 0.0f;    // radians about +Y; forward/right are relative to it (0: looking along +Z)
};

struct WorldOptions {
  int characters = 6;
  std::uint32_t seed = 1;
  // Characters stay within |x|, |z| <= arena_half_size and out of these
  // boxes (grown by a body radius).
  float arena_half_size = 12.0f;
  std::vector<Aabb> obstacles;
  // Model space -> world at the origin facing +Z, feet on y = 0, Y up, in
  // metres (the demo computes it from the model's rest bounds).
  Affine3 model_to_world = Affine3::identity();
  float walk_speed = 1.4f;  // m/s at full walk weight
  float run_speed = 3.6f;   // m/s at full run weight
  // Each character's own pace, so a crowd does not walk in step: for every
  // character but the first (the player's at the start) a factor drawn
  // from [1 - s, 1 + s] (a generator of its own, from the seed) that
  // scales its walk and run speeds and the clock of its cycles alike
  // (Mixer::set_time_factor), so its stride still matches its speed; it
  // keeps its pace when the player takes it over. In [0, 0.5]; 0: everybody
  // at the same pace.
  float pace_spread = 0.0f;
};

// The clips the controllers use, found by name in the model (case-insensitive
// substring: "idle"; "walk"; "run" or "jog"; actions "wave", "kick",
// "shoot", "punch"...); -1 where the model has none. A model needs at least a
// walk (or any looping clip, used as the walk).
struct ClipRoles {
  int idle = -1;
  int walk = -1;
  int run = -1;
  std::vector<int> actions;
};

struct CharacterState {
  Vec3 position{0.0f};    // on the floor
  float heading = 0.0f;   // radians about +Y; 0 faces +Z
  float speed = 0.0f;     // m/s, current (smoothed)
  float pace = 1.0f;      // its speeds and cycle clock over the options' (WorldOptions::pace_spread)
  bool player = false;
};

class World {
 public:
  // Errors: kInvalidArgument (characters < 1 or > 256, bad speeds, pace
  // spread or arena),
  // kNotFound when the model has no clip usable as a walk.
  static Expected<World> create(const character::Model& model, const WorldOptions& options);

  // Advances every character by dt seconds (dt <= 0 or non-finite: no
  // motion), then poses them.
  void step(float dt, const PlayerInput& input);

  int character_count() const;
  int player() const;  // index of the controlled character
  const CharacterState& character(int index) const;
  // The index-th character's skinning matrices, one per joint: bind-pose
  // model space -> world. Valid until the next step().
  std::span<const Affine3> skinning(int index) const;
  // The index-th character's mixer (for the HUD and tests).
  const anim::Mixer& mixer(int index) const;
  const ClipRoles& roles() const;
  // One-shot actions started so far, by all characters.
  std::uint64_t actions_started() const;

  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  ~World();

 private:
  struct Impl;
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The clip roles of `model` (see ClipRoles).
ClipRoles find_clip_roles(const character::Model& model);

// The headless demo's scripted player: a fixed, deterministic input
// sequence (walk, turn, run, an action, pauses, Tab once) repeating every
// few seconds, as a function of the frame number at 30 fps.
PlayerInput scripted_input(int frame);

}  // namespace sinew::demo
