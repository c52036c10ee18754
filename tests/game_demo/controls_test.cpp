// The demo's key mapping and its input scripts, checked by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "game_demo/controls.h"
#include "game_demo/input_script.h"

namespace sinew::demo {
namespace {

KeySnapshot keys(std::initializer_list<DemoKey> down) {
  KeySnapshot k;
  for (DemoKey key : down) k.set(key, true);
  return k;
}

TEST(Controls, KeysBecomeTheAxesAndOpposingKeysCancel) {
  FollowCamera camera;
  const KeySnapshot none;
  auto r = apply_controls(keys({DemoKey::kForward, DemoKey::kLeft, DemoKey::kRun}), none, 0.1f, camera);
  EXPECT_EQ(r.input.forward, 1.0f);
  EXPECT_EQ(r.input.right, -1.0f);
  EXPECT_TRUE(r.input.run);
  r = apply_controls(keys({DemoKey::kForward, DemoKey::kBack, DemoKey::kRight}), none, 0.1f, camera);
  EXPECT_EQ(r.input.forward, 0.0f);
  EXPECT_EQ(r.input.right, 1.0f);
  EXPECT_FALSE(r.input.run);
}

TEST(Controls, QAndETurnTheCameraAtTheTurnRate) {
  FollowCamera camera;
  camera.yaw = 0.5f;
  const KeySnapshot none;
  auto r = apply_controls(keys({DemoKey::kTurnRight}), none, 0.25f, camera);
  EXPECT_FLOAT_EQ(camera.yaw, 0.5f + kCameraTurnRate * 0.25f);
  EXPECT_FLOAT_EQ(r.input.camera_yaw, camera.yaw);  // the player moves relative to the turned camera
  apply_controls(keys({DemoKey::kTurnLeft}), none, 0.5f, camera);
  EXPECT_FLOAT_EQ(camera.yaw, 0.5f + kCameraTurnRate * 0.25f - kCameraTurnRate * 0.5f);
  apply_controls(keys({DemoKey::kTurnLeft, DemoKey::kTurnRight}), none, 0.5f, camera);
  EXPECT_FLOAT_EQ(camera.yaw, 0.5f + kCameraTurnRate * 0.25f - kCameraTurnRate * 0.5f);
}

TEST(Controls, SpaceTabAndF1ActOncePerPressEscWhileHeld) {
  FollowCamera camera;
  const KeySnapshot held = keys({DemoKey::kAction, DemoKey::kNextCharacter, DemoKey::kToggleHud, DemoKey::kQuit});
  const auto first = apply_controls(held, KeySnapshot{}, 0.1f, camera);
  EXPECT_TRUE(first.input.action);
  EXPECT_TRUE(first.input.next_character);
  EXPECT_TRUE(first.toggle_hud);
  EXPECT_TRUE(first.quit);
  const auto again = apply_controls(held, held, 0.1f, camera);
  EXPECT_FALSE(again.input.action);
  EXPECT_FALSE(again.input.next_character);
  EXPECT_FALSE(again.toggle_hud);
  EXPECT_TRUE(again.quit);
}

TEST(Controls, KeyNamesAndTheirAliases) {
  EXPECT_EQ(demo_key_from_name("w"), DemoKey::kForward);
  EXPECT_EQ(demo_key_from_name("up"), DemoKey::kForward);
  EXPECT_EQ(demo_key_from_name("left"), DemoKey::kLeft);
  EXPECT_EQ(demo_key_from_name("f1"), DemoKey::kToggleHud);
  EXPECT_EQ(demo_key_from_name("esc"), DemoKey::kQuit);
  EXPECT_FALSE(demo_key_from_name("W").has_value());  // names are lower case
  EXPECT_FALSE(demo_key_from_name("").has_value());
}

TEST(InputScript, KeysFollowTheEventsInFrameOrder) {
  auto script = InputScript::parse(
      "# comment line\n"
      "10 shift down\n"
      "0  w     down   # walk\n"
      "\n"
      "20 w up\r\n"
      "15 space tap\n"
      "15 up down\n",  // an alias of w: the same control
      "test.script");
  ASSERT_TRUE(script.ok()) << script.status().message();
  EXPECT_FALSE(script->keys_at(-1).down(DemoKey::kForward));
  EXPECT_TRUE(script->keys_at(0).down(DemoKey::kForward));
  EXPECT_FALSE(script->keys_at(9).down(DemoKey::kRun));
  EXPECT_TRUE(script->keys_at(10).down(DemoKey::kRun));
  EXPECT_TRUE(script->keys_at(15).down(DemoKey::kAction));
  EXPECT_FALSE(script->keys_at(16).down(DemoKey::kAction));  // a tap lasts one frame
  EXPECT_TRUE(script->keys_at(19).down(DemoKey::kForward));
  EXPECT_FALSE(script->keys_at(20).down(DemoKey::kForward));
  EXPECT_TRUE(script->keys_at(1000).down(DemoKey::kRun));  // held to the end
  EXPECT_EQ(script->last_frame(), 20);
}

TEST(InputScript, ScriptControlsGiveOneActionPerTap) {
  auto script = InputScript::parse("3 space tap\n5 e down\n", "s");
  ASSERT_TRUE(script.ok());
  FollowCamera camera;
  int actions = 0;
  for (int f = 0; f < 10; ++f) actions += script_controls(*script, f, camera).input.action ? 1 : 0;
  EXPECT_EQ(actions, 1);
  // E held on frames 5..9: five fixed steps of turning.
  EXPECT_FLOAT_EQ(camera.yaw, 5.0f * kCameraTurnRate * kScriptStepSeconds);
}

TEST(InputScript, BadLinesAreRejectedWithTheLineAndTheToken) {
  struct Case {
    const char* text;
    const char* field;
    const char* value;
  };
  const Case cases[] = {
      {"0 w down\nx w down\n", "line 2 frame", "x"},
      {"-1 w down\n", "line 1 frame", "-1"},
      {"999999999999 w down\n", "line 1 frame", "999999999999"},
      {"0 jump down\n", "line 1 key", "jump"},
      {"0 w hold\n", "line 1 event", "hold"},
      {"0 w\n", "line 1", "0 w"},
      {"0 w down now\n", "line 1", "0 w down now"},
  };
  for (const Case& c : cases) {
    auto script = InputScript::parse(c.text, "bad.script");
    ASSERT_FALSE(script.ok()) << c.text;
    EXPECT_EQ(script.status().code(), ErrorCode::kInvalidData);
    EXPECT_EQ(script.status().file(), "bad.script");
    EXPECT_EQ(script.status().field(), c.field) << c.text;
    EXPECT_EQ(script.status().value(), c.value) << c.text;
  }
}

TEST(InputScript, AMissingFileIsNotFound) {
  auto script = InputScript::load("/nonexistent/keys.script");
  ASSERT_FALSE(script.ok());
  EXPECT_EQ(script.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(script.status().message().find("/nonexistent/keys.script"), std::string::npos);
}

}  // namespace
}  // namespace sinew::demo
