#include "game_demo/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "animation/pose.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/cal3d_importer.h"

namespace sinew::demo {
namespace {

constexpr float kDt = 1.0f / 30.0f;
constexpr float kPi = std::numbers::pi_v<float>;

const character::Model& mannequin() {
  static const character::Model m = *content::make_mannequin();
  return m;
}

int clip_named(const character::Model& m, const std::string& name) {
  for (std::size_t i = 0; i < m.clips.size(); ++i) {
    if (m.clips[i].name() == name) return static_cast<int>(i);
  }
  return -1;
}

character::Model walk_only() {
  character::Model m = mannequin();
  const anim::Clip walk = m.clips[static_cast<std::size_t>(clip_named(m, "walk"))];
  m.clips = {walk};
  return m;
}

WorldOptions single(float arena = 12.0f) {
  WorldOptions o;
  o.characters = 1;
  o.arena_half_size = arena;
  return o;
}

World make_world(const WorldOptions& o, const character::Model& m = mannequin()) {
  Expected<World> w = World::create(m, o);
  EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.status().message());
  return std::move(w).value();
}

void run_steps(World& w, int steps, const PlayerInput& input) {
  for (int i = 0; i < steps; ++i) w.step(kDt, input);
}

std::vector<Aabb> some_obstacles() {
  return {Aabb{Vec3(2.0f, 0.0f, -1.0f), Vec3(3.5f, 1.5f, 1.0f)},
          Aabb{Vec3(-4.0f, 0.0f, 3.0f), Vec3(-2.5f, 2.0f, 5.0f)},
          Aabb{Vec3(-1.0f, 0.0f, -6.0f), Vec3(1.0f, 1.0f, -4.5f)},
          Aabb{Vec3(6.0f, 0.0f, 6.0f), Vec3(9.0f, 3.0f, 7.0f)}};
}

bool all_finite(std::span<const Affine3> m) {
  for (const Affine3& a : m) {
    if (!is_finite(a)) return false;
  }
  return true;
}

// The rotation about +Y written out by hand: heading h turns +Z into
// (sin h, 0, cos h), the direction the character walks.
Affine3 hand_rotation_y(float h) {
  Affine3 r;
  r.rows[0] = Vec4(std::cos(h), 0.0f, std::sin(h), 0.0f);
  r.rows[1] = Vec4(0.0f, 1.0f, 0.0f, 0.0f);
  r.rows[2] = Vec4(-std::sin(h), 0.0f, std::cos(h), 0.0f);
  return r;
}

void expect_matrices_near(std::span<const Affine3> got, std::span<const Affine3> want, float tol) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t j = 0; j < got.size(); ++j) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(got[j](r, c), want[j](r, c), tol) << "joint " << j << " (" << r << "," << c << ")";
      }
    }
  }
}

TEST(WorldRoles, MannequinHasAllRoles) {
  const ClipRoles roles = find_clip_roles(mannequin());
  EXPECT_EQ(roles.idle, clip_named(mannequin(), "idle"));
  EXPECT_EQ(roles.walk, clip_named(mannequin(), "walk"));
  EXPECT_EQ(roles.run, clip_named(mannequin(), "run"));
  ASSERT_EQ(roles.actions.size(), 2u);
  EXPECT_EQ(roles.actions[0], clip_named(mannequin(), "wave"));
  EXPECT_EQ(roles.actions[1], clip_named(mannequin(), "kick"));
  EXPECT_GE(roles.idle, 0);
}

TEST(WorldRoles, NamesMatchCaseInsensitivelyAndJogIsARun) {
  character::Model m = mannequin();
  // Rebuild the clips under other names: only the names matter here.
  std::vector<anim::Clip> renamed;
  for (const char* name : {"Paladin_Idle", "WALK_cycle", "jog", "Shoot_Arrow", "strut"}) {
    anim::RawClip raw;
    raw.name = name;
    raw.tracks = {anim::JointTracks{}};
    raw.tracks[0].rotation.times = {0.0f, 1.0f};
    raw.tracks[0].rotation.values = {Quat(1, 0, 0, 0), Quat(1, 0, 0, 0)};
    renamed.push_back(*anim::Clip::build(raw, m.skeleton, "test"));
  }
  m.clips = renamed;
  const ClipRoles roles = find_clip_roles(m);
  EXPECT_EQ(roles.idle, 0);
  EXPECT_EQ(roles.walk, 1);
  EXPECT_EQ(roles.run, 2);
  EXPECT_EQ(roles.actions, std::vector<int>{3});
}

TEST(WorldRoles, WalkOnlyModelStillMakesAWorld) {
  const character::Model m = walk_only();
  const ClipRoles roles = find_clip_roles(m);
  EXPECT_EQ(roles.idle, -1);
  EXPECT_EQ(roles.walk, 0);
  EXPECT_EQ(roles.run, -1);
  EXPECT_TRUE(roles.actions.empty());

  WorldOptions o = single();
  World w = make_world(o, m);
  PlayerInput walk;
  walk.forward = 1.0f;
  walk.action = true;  // no action clips: ignored
  run_steps(w, 30, walk);
  EXPECT_EQ(w.actions_started(), 0u);
  EXPECT_GT(w.character(0).position.z, 0.5f);
  EXPECT_FLOAT_EQ(w.mixer(0).cycle_weight(roles.walk), 1.0f);
  // Standing still with no idle: every cycle fades out and the character
  // holds the rest pose.
  run_steps(w, 30, PlayerInput{});
  EXPECT_EQ(w.mixer(0).cycle_count(), 0u);
  const anim::Skeleton& sk = m.skeleton;
  std::vector<anim::JointTransform> local(sk.joint_count());
  std::vector<Affine3> model(sk.joint_count()), skin(sk.joint_count());
  ASSERT_TRUE(anim::rest_pose(sk, local).ok());
  ASSERT_TRUE(anim::local_to_model(sk, local, model).ok());
  const CharacterState& s = w.character(0);
  const Affine3 instance = Affine3::translation(s.position) * hand_rotation_y(s.heading);
  ASSERT_TRUE(anim::skinning_matrices(sk, model, instance, skin).ok());
  expect_matrices_near(w.skinning(0), skin, 1e-5f);
}

TEST(WorldCreate, RejectsModelsWithoutAWalkAndBadOptions) {
  character::Model no_clips = mannequin();
  no_clips.clips.clear();
  Expected<World> none = World::create(no_clips, WorldOptions{});
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), ErrorCode::kNotFound);

  auto code_for = [](auto&& tweak) {
    WorldOptions o;
    tweak(o);
    Expected<World> w = World::create(mannequin(), o);
    return w.ok() ? ErrorCode::kOk : w.status().code();
  };
  EXPECT_EQ(code_for([](WorldOptions&) {}), ErrorCode::kOk);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.characters = 0; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.characters = 257; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.walk_speed = 0.0f; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.walk_speed = NAN; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.run_speed = 1.0f; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.run_speed = INFINITY; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.pace_spread = -0.1f; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.pace_spread = 0.6f; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.pace_spread = NAN; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.pace_spread = 0.5f; }), ErrorCode::kOk);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.arena_half_size = 0.0f; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.arena_half_size = NAN; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.obstacles = {Aabb{Vec3(0.0f), Vec3(NAN)}}; }),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_for([](WorldOptions& o) { o.model_to_world.rows[0].w = NAN; }),
            ErrorCode::kInvalidArgument);
  // 256 characters do not fit in a 2 m arena.
  EXPECT_EQ(code_for([](WorldOptions& o) {
              o.characters = 256;
              o.arena_half_size = 2.0f;
            }),
            ErrorCode::kInvalidArgument);
  // An empty (default) box blocks nothing and is not an error.
  EXPECT_EQ(code_for([](WorldOptions& o) { o.obstacles = {Aabb::empty()}; }), ErrorCode::kOk);
}

TEST(WorldPlacement, ALargeCrowdStartsCloserTogetherButApart) {
  // Six characters start 1.5 m apart as ever; 256 do not fit so, and start
  // closer, yet never within two body radii of each other, inside the
  // arena and outside the boxes.
  WorldOptions o;
  o.obstacles = some_obstacles();
  o.characters = 256;
  const World crowd = make_world(o);
  ASSERT_EQ(crowd.character_count(), 256);
  float closest = INFINITY;
  for (int i = 0; i < 256; ++i) {
    const Vec3 p = crowd.character(i).position;
    EXPECT_LE(std::max(std::abs(p.x), std::abs(p.z)), o.arena_half_size) << i;
    for (const Aabb& b : o.obstacles) {
      const bool inside = p.x >= b.lower.x && p.x <= b.upper.x && p.z >= b.lower.z && p.z <= b.upper.z;
      EXPECT_FALSE(inside) << i;
    }
    for (int j = 0; j < i; ++j) closest = std::min(closest, glm::length(p - crowd.character(j).position));
  }
  EXPECT_GE(closest, 0.8f);
  EXPECT_LT(closest, 1.5f * 0.9f);  // closer than a small crowd's spacing allows
  o.characters = 6;
  const World few = make_world(o);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < i; ++j) {
      EXPECT_GE(glm::length(few.character(i).position - few.character(j).position), 1.5f * 0.9f) << i << " " << j;
    }
  }
}

TEST(WorldPace, EachCharacterButTheFirstWalksAtItsOwnPace) {
  WorldOptions o;
  o.characters = 24;
  o.seed = 3;
  const World alike = make_world(o);
  o.pace_spread = 0.3f;
  World paced = make_world(o);
  EXPECT_EQ(paced.character(0).pace, 1.0f);  // the player's
  float lo = INFINITY, hi = -INFINITY;
  for (int i = 0; i < o.characters; ++i) {
    EXPECT_EQ(alike.character(i).pace, 1.0f) << i;
    const float pace = paced.character(i).pace;
    EXPECT_GE(pace, 0.7f) << i;
    EXPECT_LE(pace, 1.3f) << i;
    // The pace has a generator of its own: everybody starts where they
    // would at one pace.
    EXPECT_EQ(paced.character(i).position, alike.character(i).position) << i;
    if (i > 0) {
      lo = std::min(lo, pace);
      hi = std::max(hi, pace);
    }
  }
  EXPECT_GT(hi - lo, 0.2f);  // spread out, not one pace for all
  // Its cycles' clock runs at its pace, and it never outruns its own run.
  for (int i = 0; i < o.characters; ++i) EXPECT_EQ(paced.mixer(i).time_factor(), paced.character(i).pace) << i;
  for (int step = 0; step < 150; ++step) {
    paced.step(kDt, PlayerInput{});
    for (int i = 1; i < o.characters; ++i) {
      EXPECT_LE(paced.character(i).speed, paced.character(i).pace * o.run_speed + 1e-4f) << i;
    }
  }
}

TEST(WorldDeterminism, SameInputsGiveBitIdenticalWorlds) {
  WorldOptions o;
  o.characters = 6;
  o.seed = 7;
  o.obstacles = some_obstacles();
  World a = make_world(o);
  World moved = make_world(o);
  World b(std::move(moved));  // the mixers must survive the move
  o.seed = 8;
  World c = make_world(o);
  for (int f = 0; f < 150; ++f) {
    a.step(kDt, scripted_input(f));
    b.step(kDt, scripted_input(f));
    c.step(kDt, scripted_input(f));
  }
  bool seed_changes_something = false;
  for (int i = 0; i < a.character_count(); ++i) {
    const CharacterState& sa = a.character(i);
    const CharacterState& sb = b.character(i);
    EXPECT_EQ(std::memcmp(&sa.position, &sb.position, sizeof(Vec3)), 0) << i;
    EXPECT_EQ(std::memcmp(&sa.heading, &sb.heading, sizeof(float)), 0) << i;
    const auto ka = a.skinning(i);
    const auto kb = b.skinning(i);
    ASSERT_EQ(ka.size(), kb.size());
    EXPECT_EQ(std::memcmp(ka.data(), kb.data(), ka.size_bytes()), 0) << i;
    if (i != a.player() && sa.position != c.character(i).position) seed_changes_something = true;
  }
  EXPECT_TRUE(seed_changes_something);
}

TEST(WorldMotion, EveryoneWandersInsideTheArenaAndOutsideTheBoxes) {
  WorldOptions o;
  o.characters = 8;
  o.seed = 3;
  o.arena_half_size = 8.0f;  // small, so the edges get visited
  o.obstacles = some_obstacles();
  World w = make_world(o);
  std::vector<Vec3> start;
  for (int i = 0; i < w.character_count(); ++i) start.push_back(w.character(i).position);
  // Slightly less than the world's 0.4 m body radius, so the check does not
  // hinge on rounding at the boundary.
  constexpr float kGrow = 0.39f;
  auto check_all = [&](int frame) {
    for (int i = 0; i < w.character_count(); ++i) {
      const Vec3 p = w.character(i).position;
      ASSERT_LE(std::abs(p.x), o.arena_half_size) << "frame " << frame << " character " << i;
      ASSERT_LE(std::abs(p.z), o.arena_half_size) << "frame " << frame << " character " << i;
      ASSERT_EQ(p.y, 0.0f);
      for (const Aabb& b : o.obstacles) {
        const bool inside = p.x > b.lower.x - kGrow && p.x < b.upper.x + kGrow &&
                            p.z > b.lower.z - kGrow && p.z < b.upper.z + kGrow;
        ASSERT_FALSE(inside) << "frame " << frame << " character " << i << " at " << p.x << "," << p.z;
      }
    }
  };
  check_all(-1);
  for (int f = 0; f < 300; ++f) {
    w.step(kDt, scripted_input(f));
    check_all(f);
  }
  for (int i = 0; i < w.character_count(); ++i) {
    EXPECT_GT(glm::length(w.character(i).position - start[i]), 0.3f) << "character " << i << " never moved";
  }
}

TEST(WorldMotion, CharactersStartApartFacingVariousWays) {
  WorldOptions o;
  o.characters = 6;
  o.obstacles = some_obstacles();
  World w = make_world(o);
  EXPECT_EQ(w.character(0).heading, 0.0f);
  bool different_headings = false;
  for (int i = 0; i < w.character_count(); ++i) {
    different_headings = different_headings || w.character(i).heading != w.character(1).heading;
    for (int j = 0; j < i; ++j) {
      EXPECT_GT(glm::length(w.character(i).position - w.character(j).position), 1.0f);
    }
  }
  EXPECT_TRUE(different_headings);
}

TEST(WorldPlayer, WalksForwardAlongTheCameraView) {
  // camera_yaw 0 looks along +Z: W moves the player along +Z. It accelerates
  // at 4 m/s^2 to 1.4 m/s (0.35 s, covering 0.245 m instead of 0.49 m), so
  // 2 s cover about 2.8 - 0.245 = 2.555 m.
  World w = make_world(single());
  const Vec3 start = w.character(0).position;
  PlayerInput in;
  in.forward = 1.0f;
  run_steps(w, 60, in);
  const Vec3 d = w.character(0).position - start;
  EXPECT_NEAR(d.z, 2.555f, 0.06f);
  EXPECT_NEAR(d.x, 0.0f, 1e-5f);
  EXPECT_FLOAT_EQ(w.character(0).speed, 1.4f);
  EXPECT_TRUE(w.character(0).player);
}

TEST(WorldPlayer, CameraYawRotatesTheControls) {
  // camera_yaw = pi/2 turns the view from +Z to +X (sin, cos of the yaw):
  // W now walks along +X. The player, facing +Z, first turns a quarter turn
  // (about 0.4 s at 4 rad/s, slowed while facing away), then walks.
  World w = make_world(single());
  PlayerInput in;
  in.forward = 1.0f;
  in.camera_yaw = kPi / 2.0f;
  run_steps(w, 60, in);
  const CharacterState& s = w.character(0);
  EXPECT_NEAR(s.heading, kPi / 2.0f, 1e-4f);
  EXPECT_GT(s.position.x, 1.8f);
  EXPECT_LT(s.position.x, 2.6f);
  EXPECT_LT(std::abs(s.position.z), 0.4f);

  // Camera along +Z: its right-hand side is -X (the mannequin's left is +X),
  // so D walks along -X.
  World r = make_world(single());
  PlayerInput right;
  right.right = 1.0f;
  run_steps(r, 60, right);
  EXPECT_LT(r.character(0).position.x, -1.8f);
  EXPECT_LT(std::abs(r.character(0).position.z), 0.4f);
}

TEST(WorldPlayer, RunIsFasterThanWalk) {
  World walk = make_world(single());
  World run = make_world(single());
  PlayerInput in;
  in.forward = 1.0f;
  run_steps(walk, 60, in);
  in.run = true;
  run_steps(run, 60, in);
  EXPECT_FLOAT_EQ(run.character(0).speed, 3.6f);
  // 3.6 m/s reached after 0.9 s: 2 * 3.6 - 0.9 * 3.6 / 2 = 5.58 m.
  EXPECT_NEAR(run.character(0).position.z, 5.58f, 0.15f);
  EXPECT_GT(run.character(0).position.z, walk.character(0).position.z + 2.0f);
}

TEST(WorldBlend, CycleWeightsFollowSpeed) {
  const ClipRoles roles = find_clip_roles(mannequin());
  World w = make_world(single());
  run_steps(w, 10, PlayerInput{});
  EXPECT_FLOAT_EQ(w.mixer(0).cycle_weight(roles.idle), 1.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.walk), 0.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.run), 0.0f);

  // Half the walk speed: halfway between idle and walk.
  PlayerInput half;
  half.forward = 0.5f;
  run_steps(w, 30, half);
  EXPECT_FLOAT_EQ(w.character(0).speed, 0.7f);
  EXPECT_NEAR(w.mixer(0).cycle_weight(roles.idle), 0.5f, 1e-5f);
  EXPECT_NEAR(w.mixer(0).cycle_weight(roles.walk), 0.5f, 1e-5f);

  PlayerInput walk;
  walk.forward = 1.0f;
  run_steps(w, 30, walk);
  EXPECT_FLOAT_EQ(w.mixer(0).cycle_weight(roles.walk), 1.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.idle), 0.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.run), 0.0f);
  EXPECT_TRUE(w.mixer(0).cycle_synchronized(roles.walk));

  walk.run = true;
  run_steps(w, 45, walk);
  EXPECT_FLOAT_EQ(w.mixer(0).cycle_weight(roles.run), 1.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.walk), 0.0f);
  EXPECT_EQ(w.mixer(0).cycle_weight(roles.idle), 0.0f);
}

TEST(WorldPlayer, ActionStartsOneShotsRoundRobin) {
  const ClipRoles roles = find_clip_roles(mannequin());
  World w = make_world(single());
  PlayerInput act;
  act.action = true;
  w.step(kDt, act);
  EXPECT_TRUE(w.mixer(0).action_active(roles.actions[0]));
  EXPECT_FALSE(w.mixer(0).action_active(roles.actions[1]));
  EXPECT_EQ(w.actions_started(), 1u);
  w.step(kDt, PlayerInput{});
  EXPECT_EQ(w.actions_started(), 1u);
  w.step(kDt, act);
  EXPECT_TRUE(w.mixer(0).action_active(roles.actions[1]));
  EXPECT_EQ(w.actions_started(), 2u);
}

TEST(WorldPlayer, TabPassesControlOn) {
  WorldOptions o;
  o.characters = 3;
  World w = make_world(o);
  EXPECT_EQ(w.player(), 0);
  PlayerInput tab;
  tab.next_character = true;
  w.step(kDt, tab);
  EXPECT_EQ(w.player(), 1);
  EXPECT_FALSE(w.character(0).player);
  EXPECT_TRUE(w.character(1).player);
  EXPECT_FALSE(w.character(2).player);
  // The former player now wanders on its own; the new one stands still
  // without input.
  const Vec3 old_start = w.character(0).position;
  const Vec3 new_start = w.character(1).position;
  run_steps(w, 150, PlayerInput{});
  EXPECT_GT(glm::length(w.character(0).position - old_start), 0.3f);
  EXPECT_EQ(w.character(1).position, new_start);
  w.step(kDt, tab);
  w.step(kDt, tab);
  EXPECT_EQ(w.player(), 0);
  EXPECT_TRUE(w.character(0).player);
}

TEST(WorldPose, SettledIdleMatchesADirectSampleOfTheClip) {
  const character::Model& m = mannequin();
  const ClipRoles roles = find_clip_roles(m);
  WorldOptions o = single();
  o.model_to_world = Affine3::from_trs(Vec3(0.1f, 0.02f, -0.3f),
                                       glm::angleAxis(0.3f, glm::normalize(Vec3(1.0f, 0.0f, 1.0f))),
                                       Vec3(0.5f));
  World w = make_world(o);
  // Walk off at an angle so the instance has a position and a heading, then
  // stand until walk has faded out and idle is back at weight 1 alone.
  PlayerInput in;
  in.forward = 1.0f;
  in.camera_yaw = -2.0f;
  run_steps(w, 30, in);  // the turn takes 0.5 s; then it walks straight
  const Vec3 turned = w.character(0).position;
  run_steps(w, 15, in);
  const Vec3 straight = w.character(0).position - turned;
  run_steps(w, 45, PlayerInput{});
  const anim::Mixer& mixer = w.mixer(0);
  ASSERT_EQ(mixer.cycle_count(), 1u);
  ASSERT_EQ(mixer.action_count(), 0u);
  ASSERT_EQ(mixer.cycle_weight(roles.idle), 1.0f);

  const CharacterState& s = w.character(0);
  EXPECT_NEAR(s.heading, -2.0f, 1e-4f);
  // It walked along its heading: (sin h, cos h) on the floor.
  const float travelled = glm::length(straight);
  EXPECT_NEAR(travelled, 1.4f * 0.5f, 1e-3f);
  EXPECT_NEAR(straight.x / travelled, std::sin(-2.0f), 1e-4f);
  EXPECT_NEAR(straight.z / travelled, std::cos(-2.0f), 1e-4f);
  EXPECT_GT(glm::length(s.position), 1.0f);

  const anim::Skeleton& sk = m.skeleton;
  std::vector<anim::JointTransform> local(sk.joint_count());
  std::vector<Affine3> model(sk.joint_count()), skin(sk.joint_count());
  ASSERT_TRUE(anim::rest_pose(sk, local).ok());
  anim::SamplingCache cache;
  anim::sample_clip(m.clips[static_cast<std::size_t>(roles.idle)], mixer.cycle_time(roles.idle), cache, local);
  ASSERT_TRUE(anim::local_to_model(sk, local, model).ok());
  const Affine3 instance = Affine3::translation(s.position) * hand_rotation_y(s.heading) * o.model_to_world;
  ASSERT_TRUE(anim::skinning_matrices(sk, model, instance, skin).ok());
  expect_matrices_near(w.skinning(0), skin, 1e-5f);
}

TEST(WorldLongRun, ScriptedSixHundredStepsStayFinite) {
  WorldOptions o;
  o.obstacles = some_obstacles();
  World w = make_world(o);
  for (int f = 0; f < 600; ++f) w.step(kDt, scripted_input(f));
  for (int i = 0; i < w.character_count(); ++i) {
    EXPECT_EQ(w.skinning(i).size(), mannequin().skeleton.joint_count());
    EXPECT_TRUE(all_finite(w.skinning(i))) << i;
  }
  // Tab at 6 s and 14 s; actions by the script and by the wanderers.
  EXPECT_EQ(w.player(), 2);
  EXPECT_GE(w.actions_started(), 2u);
}

TEST(WorldStep, BadTimeStepsDoNotMove) {
  World w = make_world(single());
  PlayerInput in;
  in.forward = 1.0f;
  w.step(0.0f, in);
  w.step(-1.0f, in);
  w.step(NAN, in);
  w.step(INFINITY, in);
  EXPECT_EQ(w.character(0).position, Vec3(0.0f));
  EXPECT_EQ(w.character(0).speed, 0.0f);
  EXPECT_TRUE(all_finite(w.skinning(0)));
}

TEST(ScriptedInput, EdgesFireOnceAPeriodAndThePlayerKeepsMoving) {
  int actions = 0, tabs = 0;
  for (int f = 0; f < 480; ++f) {
    const PlayerInput in = scripted_input(f);
    actions += in.action ? 1 : 0;
    tabs += in.next_character ? 1 : 0;
    EXPECT_TRUE(std::isfinite(in.camera_yaw));
    EXPECT_LE(std::abs(in.forward), 1.0f);
    EXPECT_LE(std::abs(in.right), 1.0f);
  }
  EXPECT_EQ(actions, 2);
  EXPECT_EQ(tabs, 2);
  EXPECT_EQ(scripted_input(0).forward, 1.0f);
  EXPECT_EQ(scripted_input(0).camera_yaw, 0.0f);
  EXPECT_TRUE(scripted_input(100).run);
  EXPECT_FALSE(scripted_input(160).run);
  EXPECT_EQ(scripted_input(160).forward, 0.0f);
  // Each period turns the camera further.
  EXPECT_NE(scripted_input(0).camera_yaw, scripted_input(240).camera_yaw);
}

// Cally's .cfg lists only the walk, but the importer also picks up the
// cally_*.caf files beside it, so every role is filled.
TEST(WorldCally, Cal3dModelWorks) {
  const std::string cfg = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";
  if (!std::filesystem::exists(cfg)) GTEST_SKIP() << cfg << " not present";
  Expected<character::Model> cally = editor::import_cal3d(cfg);
  ASSERT_TRUE(cally.ok()) << cally.status().message();
  const ClipRoles roles = find_clip_roles(*cally);
  EXPECT_EQ(cally->clips[static_cast<std::size_t>(roles.walk)].name(), "walk");
  EXPECT_EQ(cally->clips[static_cast<std::size_t>(roles.idle)].name(), "idle");
  EXPECT_EQ(cally->clips[static_cast<std::size_t>(roles.run)].name(), "jog");
  std::vector<std::string> actions;
  for (int a : roles.actions) actions.push_back(cally->clips[static_cast<std::size_t>(a)].name());
  std::sort(actions.begin(), actions.end());
  EXPECT_EQ(actions, (std::vector<std::string>{"shoot_arrow", "tornado_kick", "wave"}));
  WorldOptions o;
  o.characters = 3;
  World w = make_world(o, *cally);
  for (int f = 0; f < 100; ++f) w.step(kDt, scripted_input(f));
  for (int i = 0; i < w.character_count(); ++i) EXPECT_TRUE(all_finite(w.skinning(i)));
  EXPECT_GT(w.character(0).position.z, 1.0f);
}

}  // namespace
}  // namespace sinew::demo
