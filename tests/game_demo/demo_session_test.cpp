// The demo's game loop end to end: the mannequin baked in memory, six
// characters in the arena, ray traced with shadows.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "game_demo/demo_session.h"
#include "runtime/jobs/job_system.h"

namespace sinew::demo {
namespace {

constexpr float kStep = 1.0f / 30.0f;

std::unique_ptr<DemoSession> make_session(JobSystem& jobs, std::uint32_t seed = 1) {
  SessionOptions options;
  options.width = 96;
  options.height = 96;
  options.seed = seed;
  auto session = DemoSession::create(options, jobs);
  EXPECT_TRUE(session.ok()) << session.status().message();
  return session.ok() ? std::move(*session) : nullptr;
}

std::vector<std::uint8_t> run_frames(DemoSession& session, JobSystem& jobs, int first, int count) {
  FollowCamera camera;
  for (int f = first; f < first + count; ++f) {
    const PlayerInput input = scripted_input(f);
    camera.yaw = input.camera_yaw;
    auto report = session.frame(kStep, input, camera, jobs);
    EXPECT_TRUE(report.ok()) << report.status().message();
  }
  return {session.rgba().begin(), session.rgba().end()};
}

TEST(DemoSession, TheScriptedRunIsDeterministicForAThreadCount) {
  JobSystem jobs(2);
  auto a = make_session(jobs);
  auto b = make_session(jobs);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(run_frames(*a, jobs, 0, 12), run_frames(*b, jobs, 0, 12));
  // And one thread draws the same pixels (the renderer's tiles are independent).
  JobSystem one(1);
  auto c = make_session(one);
  ASSERT_TRUE(c);
  EXPECT_EQ(run_frames(*c, one, 0, 12), std::vector<std::uint8_t>(a->rgba().begin(), a->rgba().end()));
}

TEST(DemoSession, CharactersMoveAndAnimate) {
  JobSystem jobs(2);
  auto session = make_session(jobs);
  ASSERT_TRUE(session);
  const auto first = run_frames(*session, jobs, 0, 1);
  std::vector<Vec3> start;
  for (int i = 0; i < session->world().character_count(); ++i) start.push_back(session->world().character(i).position);
  const auto later = run_frames(*session, jobs, 1, 45);
  EXPECT_NE(first, later);
  int moved = 0;
  for (int i = 0; i < session->world().character_count(); ++i) {
    moved += glm::length(session->world().character(i).position - start[static_cast<std::size_t>(i)]) > 0.2f ? 1 : 0;
  }
  EXPECT_GE(moved, 2);  // the player walks; NPCs pause now and then
  EXPECT_EQ(session->world().character_count(), 6);
}

TEST(DemoSession, ACrowdOf256FitsTheArenaAndRenders) {
  // --characters takes up to 256: a crowd too large for the usual start
  // spacing starts closer together, between the arena's obstacles.
  JobSystem jobs(2);
  SessionOptions options;
  options.width = 32;
  options.height = 32;
  options.characters = 256;
  auto session = DemoSession::create(options, jobs);
  ASSERT_TRUE(session.ok()) << session.status().message();
  EXPECT_EQ((*session)->world().character_count(), 256);
  run_frames(**session, jobs, 0, 2);
}

TEST(DemoSession, CharactersCastShadowsOnTheGround) {
  JobSystem jobs(2);
  auto session = make_session(jobs);
  ASSERT_TRUE(session);
  // The same frame with and without shadow rays: the world is stepped by 0 s
  // for the second render, so only the shadows differ.
  const auto lit = [&](bool shadows) {
    session->render_settings().shadows = shadows;
    FollowCamera camera;
    auto report = session->frame(shadows ? kStep : 0.0f, PlayerInput{}, camera, jobs);
    EXPECT_TRUE(report.ok());
    return std::vector<std::uint8_t>(session->rgba().begin(), session->rgba().end());
  };
  const auto with = lit(true);
  const auto without = lit(false);
  ASSERT_EQ(with.size(), without.size());
  int darker = 0, brighter = 0;
  for (std::size_t i = 0; i < with.size(); i += 4) {
    darker += with[i + 1] + 8 < without[i + 1] ? 1 : 0;
    brighter += with[i + 1] > without[i + 1] ? 1 : 0;
  }
  EXPECT_GT(darker, 30);      // the player's shadow in front of the camera at least
  EXPECT_EQ(brighter, 0);     // shadows only ever remove light
}

// --light: the session shades with every light it is given (the renderer's
// brute-force test checks each light's share; this checks the demo hands
// them all on). One light per colour channel: with shadows each channel
// darkens somewhere, so each light casts its own shadow rays.
TEST(DemoSession, EveryLightGivenCastsItsOwnShadows) {
  JobSystem jobs(2);
  SessionOptions options;
  options.width = 96;
  options.height = 96;
  options.lights.resize(3);
  options.lights[0].position = Vec3(6.0f, 12.0f, 4.0f);
  options.lights[0].color = Vec3(1.0f, 0.0f, 0.0f);
  options.lights[1].position = Vec3(-5.0f, 8.0f, 6.0f);
  options.lights[1].color = Vec3(0.0f, 1.0f, 0.0f);
  options.lights[2].kind = rt::Light::Kind::kDirectional;
  options.lights[2].direction = Vec3(0.3f, 1.0f, -0.6f);
  options.lights[2].color = Vec3(0.0f, 0.0f, 1.0f);
  auto created = DemoSession::create(options, jobs);
  ASSERT_TRUE(created.ok()) << created.status().message();
  DemoSession& session = **created;
  ASSERT_EQ(session.render_settings().lights.size(), 3u);
  const auto lit = [&](bool shadows) {
    session.render_settings().shadows = shadows;
    FollowCamera camera;
    auto report = session.frame(shadows ? kStep : 0.0f, PlayerInput{}, camera, jobs);
    EXPECT_TRUE(report.ok());
    return std::vector<std::uint8_t>(session.rgba().begin(), session.rgba().end());
  };
  const auto with = lit(true);
  const auto without = lit(false);
  for (std::size_t c = 0; c < 3; ++c) {
    int darker = 0, brighter = 0;
    for (std::size_t i = 0; i < with.size(); i += 4) {
      darker += with[i + c] + 8 < without[i + c] ? 1 : 0;
      brighter += with[i + c] > without[i + c] ? 1 : 0;
    }
    EXPECT_GT(darker, 10) << "light " << c << " casts no shadow";
    EXPECT_EQ(brighter, 0) << "light " << c;
  }
}

TEST(DemoSession, BadModelPathsAreClearErrors) {
  JobSystem jobs(1);
  SessionOptions options;
  options.model_path = "/nonexistent/character.pack";
  auto missing = DemoSession::create(options, jobs);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/nonexistent/character.pack"), std::string::npos);
  options.model_path = "character.fbx";
  auto unknown = DemoSession::create(options, jobs);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find(".fbx"), std::string::npos);
}

// The demo loads baked content only: a source model is refused with the
// editor command that bakes it, before any file is read.
TEST(DemoSession, SourceModelsAreRefusedWithTheBakeCommand) {
  JobSystem jobs(1);
  for (const std::string path : {"/data/hero.glb", "/data/hero.gltf", "/data/cally.cfg"}) {
    SessionOptions options;
    options.model_path = path;
    auto session = DemoSession::create(options, jobs);
    ASSERT_FALSE(session.ok()) << path;
    EXPECT_EQ(session.status().code(), ErrorCode::kInvalidArgument) << path;
    EXPECT_NE(session.status().message().find("sinew-editor bake " + path), std::string::npos)
        << session.status().message();
  }
}

// The mannequin baked into a pack with the demo's own settings (every clip,
// keys + 30 Hz) plays exactly as the mannequin baked at start-up.
TEST(DemoSession, ABakedPackPlaysLikeTheInMemoryBake) {
  JobSystem jobs(2);
  auto mannequin = content::make_mannequin();
  ASSERT_TRUE(mannequin.ok());
  auto baked = character::bake_in_memory(*mannequin, character::BakeRequest{}, jobs);
  ASSERT_TRUE(baked.ok());
  character::PackContents contents;
  contents.model = &*mannequin;
  contents.fuzzy = &baked->fuzzy;
  contents.pose_space.desc = character::BakeRequest{}.pose_space;
  const std::string path = (std::filesystem::path(testing::TempDir()) / "demo_mannequin.pack").string();
  ASSERT_TRUE(character::write_pack(path, contents).ok());

  SessionOptions options;
  options.width = 96;
  options.height = 96;
  options.model_path = path;
  auto from_pack = DemoSession::create(options, jobs);
  ASSERT_TRUE(from_pack.ok()) << from_pack.status().message();
  EXPECT_TRUE((*from_pack)->bake_info().from_pack);
  auto in_memory = make_session(jobs);
  ASSERT_TRUE(in_memory);
  EXPECT_FALSE(in_memory->bake_info().from_pack);
  EXPECT_EQ(run_frames(**from_pack, jobs, 0, 20), run_frames(*in_memory, jobs, 0, 20));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sinew::demo
