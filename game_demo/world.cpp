#include "game_demo/world.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <random>
#include <string>
#include <string_view>
#include <utility>

#include "animation/blend.h"
#include "animation/pose.h"

namespace sinew::demo {
namespace {

constexpr int kMaxCharacters = 256;
constexpr float kMaxPaceSpread = 0.5f;
constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;

// Locomotion tuning. A body radius keeps feet and arms out of the boxes; the
// turn rate and accelerations make starts, stops and turns read as motion
// rather than teleports without feeling sluggish under the keys.
constexpr float kBodyRadius = 0.4f;
constexpr float kTurnRate = 4.0f;       // rad/s
constexpr float kAcceleration = 4.0f;   // m/s^2 when speeding up
constexpr float kDeceleration = 8.0f;   // m/s^2 when slowing down (stops stay short)
constexpr float kBlendDelay = 0.2f;     // s, cycle weight fades
constexpr float kActionFadeIn = 0.2f;   // s
constexpr float kActionFadeOut = 0.3f;  // s
// Movement and the wander logic advance in sub-steps no longer than this so
// that a long frame cannot carry a character through a (grown) box.
constexpr float kMaxSubstep = 1.0f / 30.0f;
// A hitch longer than this is simulated as this long.
constexpr float kMaxStep = 1.0f;
// Spacing of the start positions (centre, then rings). A crowd that does
// not fit at that spacing starts closer, down to kMinStartSpacing (two body
// radii and a little room), tried in kStartSpacingStep steps.
constexpr float kStartSpacing = 1.5f;
constexpr float kMinStartSpacing = 0.9f;
constexpr float kStartSpacingStep = 0.15f;

// NPC behaviour.
constexpr float kArriveDistance = 0.4f;  // m
constexpr float kRunChance = 0.25f;      // of walks
constexpr float kActionChance = 0.2f;    // of pauses, when the model has actions
constexpr float kMaxWalkTime = 20.0f;    // s before giving up on a target

// [0, 1) from the generator's raw 32-bit output: the top 24 bits are exact
// in a float, so the result never rounds up to 1.
float unit_float(std::mt19937& rng) {
  return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f);
}

float in_range(std::mt19937& rng, float lo, float hi) { return lo + (hi - lo) * unit_float(rng); }

// The signed angle from a to b, in [-pi, pi].
float angle_difference(float from, float to) {
  float d = std::remainder(to - from, kTwoPi);
  if (d < -kPi) d += kTwoPi;
  if (d > kPi) d -= kTwoPi;
  return d;
}

float wrap_angle(float a) { return std::remainder(a, kTwoPi); }

Vec3 heading_direction(float heading) { return {std::sin(heading), 0.0f, std::cos(heading)}; }

Affine3 rotation_y(float angle) {
  return Affine3::from_trs(Vec3(0.0f), glm::angleAxis(angle, Vec3(0.0f, 1.0f, 0.0f)), Vec3(1.0f));
}

std::string lower_case(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool contains_any(const std::string& haystack, std::initializer_list<std::string_view> needles) {
  return std::any_of(needles.begin(), needles.end(),
                     [&](std::string_view n) { return haystack.find(n) != std::string::npos; });
}

// Obstacles as the floor sees them: their x/z footprint grown by the body
// radius. Characters stand on y = 0, so a box's height does not matter.
struct Footprint {
  float min_x, max_x, min_z, max_z;
  bool contains(const Vec3& p) const {
    return p.x >= min_x && p.x <= max_x && p.z >= min_z && p.z <= max_z;
  }
};

enum class NpcState { kPause, kWalk };

struct Npc {
  NpcState state = NpcState::kPause;
  float timer = 0.0f;  // pause left, or time spent walking
  Vec3 target{0.0f};
  bool run = false;
};

struct Character {
  explicit Character(std::span<const anim::Clip> clips) : mixer(clips) {}

  CharacterState state;
  anim::Mixer mixer;
  std::mt19937 rng;
  Npc npc;
  // The cycle weights last handed to the mixer, per role (idle, walk, run):
  // re-issuing an unchanged target would restart its fade every step.
  std::array<float, 3> cycle_target{-1.0f, -1.0f, -1.0f};
  // Reused every step so that posing allocates nothing once warmed up.
  std::vector<anim::SamplingCache> caches;
  anim::BlendScratch scratch;
  std::vector<anim::JointTransform> local;
  std::vector<Affine3> model_pose;
  std::vector<Affine3> skin;
};

// What a controller asks of the locomotion for one sub-step.
struct Intent {
  bool has_direction = false;
  float heading = 0.0f;
  float speed = 0.0f;
};

Status validate(const WorldOptions& o) {
  if (o.characters < 1 || o.characters > kMaxCharacters) {
    return invalid_argument("characters", std::to_string(o.characters),
                            "must be in [1, " + std::to_string(kMaxCharacters) + "]");
  }
  if (!std::isfinite(o.arena_half_size) || o.arena_half_size < 1.0f || o.arena_half_size > 1.0e4f) {
    return invalid_argument("arena_half_size", std::to_string(o.arena_half_size),
                            "must be finite and in [1, 10000] metres");
  }
  if (!std::isfinite(o.walk_speed) || o.walk_speed <= 0.0f || o.walk_speed > 100.0f) {
    return invalid_argument("walk_speed", std::to_string(o.walk_speed),
                            "must be finite and in (0, 100] m/s");
  }
  if (!std::isfinite(o.run_speed) || o.run_speed <= o.walk_speed || o.run_speed > 100.0f) {
    return invalid_argument("run_speed", std::to_string(o.run_speed),
                            "must be finite, above walk_speed and at most 100 m/s");
  }
  if (!(o.pace_spread >= 0.0f && o.pace_spread <= kMaxPaceSpread)) {
    return invalid_argument("pace_spread", std::to_string(o.pace_spread), "must be in [0, 0.5]");
  }
  if (!is_finite(o.model_to_world)) {
    return invalid_argument("model_to_world", "non-finite", "must be a finite transform");
  }
  for (std::size_t i = 0; i < o.obstacles.size(); ++i) {
    const Aabb& b = o.obstacles[i];
    if (b.is_empty()) continue;  // an empty box blocks nothing
    const bool finite = std::isfinite(b.lower.x) && std::isfinite(b.lower.y) && std::isfinite(b.lower.z) &&
                        std::isfinite(b.upper.x) && std::isfinite(b.upper.y) && std::isfinite(b.upper.z);
    if (!finite) {
      return invalid_argument("obstacles[" + std::to_string(i) + "]", "non-finite",
                              "box corners must be finite");
    }
  }
  return Status{};
}

}  // namespace

ClipRoles find_clip_roles(const character::Model& model) {
  ClipRoles roles;
  const int count = static_cast<int>(model.clips.size());
  std::vector<std::string> names;
  names.reserve(model.clips.size());
  for (const anim::Clip& c : model.clips) names.push_back(lower_case(c.name()));
  // Cycles need tracks (the mixer refuses empty clips as cycles).
  auto loopable = [&](int i) { return !model.clips[static_cast<std::size_t>(i)].tracks().empty(); };
  auto first_named = [&](std::initializer_list<std::string_view> keys, auto&& extra_ok) {
    for (std::string_view key : keys) {  // earlier keys win ("run" before "jog")
      for (int i = 0; i < count; ++i) {
        if (names[static_cast<std::size_t>(i)].find(key) != std::string::npos && loopable(i) &&
            extra_ok(i)) {
          return i;
        }
      }
    }
    return -1;
  };
  auto any = [](int) { return true; };
  roles.idle = first_named({"idle"}, any);
  roles.walk = first_named({"walk"}, [&](int i) { return i != roles.idle; });
  roles.run = first_named({"run", "jog"}, [&](int i) { return i != roles.idle && i != roles.walk; });
  for (int i = 0; i < count; ++i) {
    if (i == roles.idle || i == roles.walk || i == roles.run) continue;
    if (contains_any(names[static_cast<std::size_t>(i)],
                     {"wave", "kick", "shoot", "punch", "jump", "attack", "throw", "cheer", "salute"})) {
      roles.actions.push_back(i);
    }
  }
  if (roles.walk < 0) {
    // No walk by name: any other looping clip walks; failing that the run,
    // then the idle, stands in for it (a model that can move beats none).
    for (int i = 0; i < count && roles.walk < 0; ++i) {
      const bool taken = i == roles.idle || i == roles.run ||
                         std::find(roles.actions.begin(), roles.actions.end(), i) != roles.actions.end();
      if (!taken && loopable(i)) roles.walk = i;
    }
    if (roles.walk < 0 && roles.run >= 0) std::swap(roles.walk, roles.run);
    if (roles.walk < 0 && roles.idle >= 0) std::swap(roles.walk, roles.idle);
  }
  return roles;
}

struct World::Impl {
  // Only what posing needs is copied (not the mesh): the mixers keep spans
  // into `clips`, which lives as long as the Impl and never reallocates.
  anim::Skeleton skeleton;
  std::vector<anim::Clip> clips;
  WorldOptions options;
  ClipRoles roles;
  std::vector<Footprint> footprints;
  std::vector<Character> characters;
  int player = 0;
  std::size_t next_player_action = 0;
  std::uint64_t actions_started = 0;

  bool blocked(const Vec3& p) const {
    return std::any_of(footprints.begin(), footprints.end(),
                       [&](const Footprint& f) { return f.contains(p); });
  }
  Vec3 clamp_to_arena(Vec3 p) const {
    const float h = options.arena_half_size - kBodyRadius;
    p.x = std::clamp(p.x, -h, h);
    p.z = std::clamp(p.z, -h, h);
    return p;
  }

  Status place_characters();
  std::vector<Vec3> start_spots(float spacing) const;
  void start_action(Character& c, int clip);
  void enter_pause(Character& c, bool allow_action);
  bool pick_target(Character& c);
  Intent player_intent(const Character& c, const PlayerInput& input) const;
  Intent npc_intent(Character& c, float dt);
  bool advance(Character& c, const Intent& intent, float dt);
  void set_cycle_weights(Character& c);
  void pose(Character& c);
};

std::vector<Vec3> World::Impl::start_spots(float spacing) const {
  // Candidates: the centre, then rings `spacing` apart with about `spacing`
  // between neighbours, each ring turned a little so the rings do not line
  // up. Spots in a box, outside the arena or too close to an earlier
  // character are skipped; at most options.characters are returned.
  const float limit = options.arena_half_size - kBodyRadius;
  const int rings = static_cast<int>(std::ceil(limit * std::numbers::sqrt2_v<float> / spacing)) + 1;
  std::vector<Vec3> spots;
  auto try_spot = [&](const Vec3& p) {
    if (std::abs(p.x) > limit || std::abs(p.z) > limit || blocked(p)) return;
    for (const Vec3& q : spots) {
      if (glm::length(p - q) < 0.9f * spacing) return;
    }
    spots.push_back(p);
  };
  try_spot(Vec3(0.0f));
  for (int ring = 1; ring <= rings && static_cast<int>(spots.size()) < options.characters; ++ring) {
    const float radius = spacing * static_cast<float>(ring);
    const int n = static_cast<int>(std::floor(kTwoPi * static_cast<float>(ring)));
    for (int k = 0; k < n && static_cast<int>(spots.size()) < options.characters; ++k) {
      const float a = 0.5f * static_cast<float>(ring) + kTwoPi * static_cast<float>(k) / static_cast<float>(n);
      try_spot(Vec3(radius * std::sin(a), 0.0f, radius * std::cos(a)));
    }
  }
  return spots;
}

Status World::Impl::place_characters() {
  // The widest spacing the crowd fits at: a small crowd starts where it
  // always did, a large one closer together.
  std::vector<Vec3> spots;
  for (int step = 0;; ++step) {
    const float spacing = kStartSpacing - kStartSpacingStep * static_cast<float>(step);
    if (spacing < kMinStartSpacing - 1e-3f) break;
    spots = start_spots(spacing);
    if (static_cast<int>(spots.size()) >= options.characters) break;
  }
  if (static_cast<int>(spots.size()) < options.characters) {
    return invalid_argument("characters", std::to_string(options.characters),
                            "only " + std::to_string(spots.size()) +
                                " fit in the arena outside the obstacles");
  }
  for (int i = 0; i < options.characters; ++i) {
    Character& c = characters[static_cast<std::size_t>(i)];
    c.state.position = spots[static_cast<std::size_t>(i)];
    // The player starts facing away from the default camera; the others
    // face wherever their own generator says.
    c.state.heading = i == 0 ? 0.0f : in_range(c.rng, -kPi, kPi);
  }
  return Status{};
}

void World::Impl::start_action(Character& c, int clip) {
  if (c.mixer.execute_action(clip, kActionFadeIn, kActionFadeOut).ok()) ++actions_started;
}

void World::Impl::enter_pause(Character& c, bool allow_action) {
  c.npc.state = NpcState::kPause;
  c.npc.timer = in_range(c.rng, 1.0f, 3.0f);
  // Draw even when there are no actions, so a model's action list does not
  // change where everybody walks.
  const float roll = unit_float(c.rng);
  const float which = unit_float(c.rng);
  if (allow_action && !roles.actions.empty() && roll < kActionChance) {
    const auto n = roles.actions.size();
    const auto k = std::min(n - 1, static_cast<std::size_t>(which * static_cast<float>(n)));
    start_action(c, roles.actions[k]);
  }
}

bool World::Impl::pick_target(Character& c) {
  const float h = options.arena_half_size - 2.0f * kBodyRadius;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const Vec3 t(in_range(c.rng, -h, h), 0.0f, in_range(c.rng, -h, h));
    if (blocked(t) || glm::length(t - c.state.position) < 2.0f * kArriveDistance) continue;
    c.npc.state = NpcState::kWalk;
    c.npc.target = t;
    c.npc.timer = 0.0f;
    c.npc.run = unit_float(c.rng) < kRunChance;
    return true;
  }
  return false;
}

Intent World::Impl::player_intent(const Character& c, const PlayerInput& input) const {
  (void)c;
  auto axis = [](float v) { return std::isfinite(v) ? std::clamp(v, -1.0f, 1.0f) : 0.0f; };
  const float yaw = std::isfinite(input.camera_yaw) ? input.camera_yaw : 0.0f;
  // Camera basis on the floor: forward along the view, right = forward x up
  // (looking along +Z with Y up, the right hand points to -X).
  const Vec3 forward(std::sin(yaw), 0.0f, std::cos(yaw));
  const Vec3 right(-std::cos(yaw), 0.0f, std::sin(yaw));
  Vec3 wish = axis(input.forward) * forward + axis(input.right) * right;
  float amount = glm::length(wish);
  Intent intent;
  if (amount < 1.0e-3f) return intent;
  if (amount > 1.0f) {
    wish /= amount;  // diagonals are no faster
    amount = 1.0f;
  }
  intent.has_direction = true;
  intent.heading = std::atan2(wish.x, wish.z);
  intent.speed = c.state.pace * amount * (input.run ? options.run_speed : options.walk_speed);
  return intent;
}

Intent World::Impl::npc_intent(Character& c, float dt) {
  Npc& npc = c.npc;
  Intent intent;
  if (npc.state == NpcState::kPause) {
    npc.timer -= dt;
    if (npc.timer <= 0.0f && !pick_target(c)) npc.timer = 1.0f;  // boxed in: wait
    if (npc.state == NpcState::kPause) return intent;
  }
  npc.timer += dt;
  const Vec3 to_target = npc.target - c.state.position;
  const float distance = std::hypot(to_target.x, to_target.z);
  if (distance < kArriveDistance || npc.timer > kMaxWalkTime) {
    enter_pause(c, true);
    return intent;
  }
  intent.has_direction = true;
  intent.heading = std::atan2(to_target.x, to_target.z);
  intent.speed = c.state.pace * (npc.run ? options.run_speed : options.walk_speed);
  return intent;
}

// Turns, accelerates and moves one character; returns false when a box or
// the arena edge stopped the step outright (sliding along it is fine).
bool World::Impl::advance(Character& c, const Intent& intent, float dt) {
  CharacterState& s = c.state;
  float target_speed = 0.0f;
  if (intent.has_direction) {
    const float error = angle_difference(s.heading, intent.heading);
    const float max_turn = kTurnRate * dt;
    s.heading = wrap_angle(s.heading + std::clamp(error, -max_turn, max_turn));
    // Slow down for sharp turns rather than sliding sideways: facing away,
    // a character turns on the spot.
    const float remaining = angle_difference(s.heading, intent.heading);
    target_speed = intent.speed * std::max(0.0f, std::cos(remaining));
  }
  const float change = target_speed - s.speed;
  const float max_change = (change > 0.0f ? kAcceleration : kDeceleration) * dt;
  s.speed = std::abs(change) <= max_change ? target_speed : s.speed + std::copysign(max_change, change);
  if (s.speed <= 0.0f || dt <= 0.0f) return true;

  const Vec3 step = heading_direction(s.heading) * (s.speed * dt);
  const std::array<Vec3, 3> tries{step, Vec3(step.x, 0.0f, 0.0f), Vec3(0.0f, 0.0f, step.z)};
  const bool x_first = std::abs(step.x) >= std::abs(step.z);
  for (int k = 0; k < 3; ++k) {
    // Slide along the longer free axis first.
    const int index = k == 0 ? 0 : ((k == 1) == x_first ? 1 : 2);
    const Vec3 wanted = s.position + tries[static_cast<std::size_t>(index)];
    const Vec3 candidate = clamp_to_arena(wanted);
    if (blocked(candidate)) continue;
    s.position = candidate;
    return k == 0 && candidate == wanted;
  }
  return false;
}

void World::Impl::set_cycle_weights(Character& c) {
  // Piecewise-linear in speed: idle 1 at rest, walk 1 at walk_speed, run 1
  // from run_speed on. A missing run leaves the walk at 1 above walk_speed;
  // a missing idle leaves no cycle at rest, so the character stands in the
  // rest pose (Cal3D normalises cycle weights, so a lone walk fading out
  // still poses fully until it is gone).
  const float v = c.state.speed;
  const float walk_v = c.state.pace * options.walk_speed, run_v = c.state.pace * options.run_speed;
  std::array<float, 3> w{0.0f, 0.0f, 0.0f};  // idle, walk, run
  if (v < walk_v) {
    w[1] = v / walk_v;
    w[0] = 1.0f - w[1];
  } else if (v < run_v) {
    w[2] = (v - walk_v) / (run_v - walk_v);
    w[1] = 1.0f - w[2];
  } else {
    w[2] = 1.0f;
  }
  if (roles.run < 0) {
    w[1] += w[2];
    w[2] = 0.0f;
  }
  const std::array<int, 3> clip{roles.idle, roles.walk, roles.run};
  for (std::size_t r = 0; r < 3; ++r) {
    if (clip[r] < 0 || w[r] == c.cycle_target[r]) continue;
    c.cycle_target[r] = w[r];
    // Cannot fail: the roles are in range, have tracks and w is in [0, 1].
    (void)c.mixer.blend_cycle(clip[r], w[r], kBlendDelay);
  }
}

void World::Impl::pose(Character& c) {
  const Status evaluated =
      anim::evaluate_layers(skeleton, clips, c.mixer.layers(), c.caches, c.local, &c.scratch);
  if (!evaluated.ok()) (void)anim::rest_pose(skeleton, c.local);  // unreachable with valid layers
  (void)anim::local_to_model(skeleton, c.local, c.model_pose);
  const Affine3 instance = Affine3::translation(c.state.position) * rotation_y(c.state.heading) *
                           options.model_to_world;
  (void)anim::skinning_matrices(skeleton, c.model_pose, instance, c.skin);
}

Expected<World> World::create(const character::Model& model, const WorldOptions& options) {
  SINEW_RETURN_IF_ERROR(validate(options));
  ClipRoles roles = find_clip_roles(model);
  if (roles.walk < 0) {
    return make_error(ErrorCode::kNotFound, model.source, "clips", std::to_string(model.clips.size()) + " clips",
                      "no clip with tracks to use as a walk cycle");
  }
  auto impl = std::make_unique<Impl>();
  impl->skeleton = model.skeleton;
  impl->clips = model.clips;
  impl->options = options;
  impl->roles = std::move(roles);
  for (const Aabb& b : options.obstacles) {
    if (b.is_empty()) continue;
    impl->footprints.push_back(
        {b.lower.x - kBodyRadius, b.upper.x + kBodyRadius, b.lower.z - kBodyRadius, b.upper.z + kBodyRadius});
  }
  const std::size_t joints = impl->skeleton.joint_count();
  impl->characters.reserve(static_cast<std::size_t>(options.characters));
  for (int i = 0; i < options.characters; ++i) {
    Character& c = impl->characters.emplace_back(impl->clips);
    c.rng.seed(options.seed + static_cast<std::uint32_t>(i));
    c.caches.resize(impl->clips.size());
    for (std::size_t k = 0; k < impl->clips.size(); ++k) c.caches[k].reset(impl->clips[k]);
    c.local.resize(joints);
    c.model_pose.resize(joints);
    c.skin.resize(joints);
  }
  SINEW_RETURN_IF_ERROR(impl->place_characters());
  impl->characters[0].state.player = true;
  for (std::size_t i = 0; i < impl->characters.size(); ++i) {
    Character& c = impl->characters[i];
    if (i > 0) {
      c.npc.state = NpcState::kPause;
      c.npc.timer = in_range(c.rng, 0.5f, 2.0f);
    }
    if (i > 0 && options.pace_spread > 0.0f) {
      // A generator of its own, so the pace leaves the wandering as it was.
      std::mt19937 pace_rng(options.seed ^ (0x9E3779B9u * static_cast<std::uint32_t>(i)));
      c.state.pace = 1.0f + options.pace_spread * (2.0f * unit_float(pace_rng) - 1.0f);
      (void)c.mixer.set_time_factor(c.state.pace);  // finite: cannot fail
    }
    // Start in the settled rest-speed blend rather than fading in from T-pose.
    impl->set_cycle_weights(c);
    c.mixer.update(kBlendDelay);
    impl->pose(c);
  }
  return World(std::move(impl));
}

void World::step(float dt, const PlayerInput& input) {
  Impl& w = *impl_;
  float h = std::isfinite(dt) && dt > 0.0f ? std::min(dt, kMaxStep) : 0.0f;

  if (input.next_character) {
    Character& old_player = w.characters[static_cast<std::size_t>(w.player)];
    old_player.state.player = false;
    w.enter_pause(old_player, false);
    w.player = (w.player + 1) % static_cast<int>(w.characters.size());
    w.characters[static_cast<std::size_t>(w.player)].state.player = true;
  }
  if (input.action && !w.roles.actions.empty()) {
    const int clip = w.roles.actions[w.next_player_action % w.roles.actions.size()];
    ++w.next_player_action;
    w.start_action(w.characters[static_cast<std::size_t>(w.player)], clip);
  }

  const int substeps = h > 0.0f ? std::max(1, static_cast<int>(std::ceil(h / kMaxSubstep - 1.0e-3f))) : 0;
  const float sub = substeps > 0 ? h / static_cast<float>(substeps) : 0.0f;
  for (Character& c : w.characters) {
    for (int s = 0; s < substeps; ++s) {
      if (c.state.player) {
        (void)w.advance(c, w.player_intent(c, input), sub);
      } else {
        const Intent intent = w.npc_intent(c, sub);
        // Walking into a box or the edge: give up on this target.
        if (!w.advance(c, intent, sub) && c.npc.state == NpcState::kWalk && !w.pick_target(c)) {
          w.enter_pause(c, false);
        }
      }
    }
    w.set_cycle_weights(c);
    c.mixer.update(h);
    w.pose(c);
  }
}

World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

int World::character_count() const { return static_cast<int>(impl_->characters.size()); }
int World::player() const { return impl_->player; }
const CharacterState& World::character(int index) const {
  return impl_->characters[static_cast<std::size_t>(index)].state;
}
std::span<const Affine3> World::skinning(int index) const {
  return impl_->characters[static_cast<std::size_t>(index)].skin;
}
const anim::Mixer& World::mixer(int index) const {
  return impl_->characters[static_cast<std::size_t>(index)].mixer;
}
const ClipRoles& World::roles() const { return impl_->roles; }
std::uint64_t World::actions_started() const { return impl_->actions_started; }

PlayerInput scripted_input(int frame) {
  constexpr int kFps = 30;
  constexpr int kPeriod = 8 * kFps;
  const int f = ((frame % kPeriod) + kPeriod) % kPeriod;
  const int cycle = (frame - f) / kPeriod;
  const float t = static_cast<float>(f) / static_cast<float>(kFps);
  // The camera turns 0.6 rad during second 2 of every cycle and keeps that,
  // so successive cycles head off in new directions instead of pinning the
  // player against one wall.
  constexpr float kTurnPerCycle = 0.6f;
  const float turn = kTurnPerCycle * std::clamp(t - 2.0f, 0.0f, 1.0f);
  PlayerInput in;
  in.camera_yaw = wrap_angle(kTurnPerCycle * static_cast<float>(cycle % 1000) + turn);
  if (t < 2.0f) {
    in.forward = 1.0f;  // walk
  } else if (t < 3.0f) {
    in.forward = 1.0f;  // walk diagonally while the camera turns
    in.right = 1.0f;
  } else if (t < 5.0f) {
    in.forward = 1.0f;  // run
    in.run = true;
  } else if (t < 6.0f) {
    in.action = f == 5 * kFps;  // stand; one action on the first frame
  } else if (t < 7.0f) {
    in.next_character = f == 6 * kFps;  // Tab once, then the new player sidesteps left
    in.right = -1.0f;
  }
  return in;
}

}  // namespace sinew::demo
