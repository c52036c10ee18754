// The demo's real window under Xvfb: GLFW, the PBO display, the ImGui HUD
// and the key handling, driven by an input script. A scripted window run
// steps the world exactly like a scripted headless run, so what the window
// shows (read back from its framebuffer) must be the headless frame, pixel
// for pixel, wherever the HUD does not cover it.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "game_demo/demo_session.h"
#include "game_demo/input_script.h"
#include "game_demo/window_loop.h"
#include "runtime/display/window.h"
#include "runtime/jobs/job_system.h"

namespace sinew::demo {
namespace {

constexpr int kSize = 480;

std::unique_ptr<DemoSession> make_session(JobSystem& jobs) {
  SessionOptions options;
  options.width = kSize;
  options.height = kSize;
  options.characters = 3;
  auto session = DemoSession::create(options, jobs);
  EXPECT_TRUE(session.ok()) << session.status().message();
  return session.ok() ? std::move(*session) : nullptr;
}

// The headless frame after `frames` scripted frames.
std::vector<std::uint8_t> headless_frame(const InputScript& script, int frames) {
  JobSystem jobs(2);
  auto session = make_session(jobs);
  if (!session) return {};
  FollowCamera camera;
  for (int f = 0; f < frames; ++f) {
    const ControlResult control = script_controls(script, f, camera);
    auto report = session->frame(kScriptStepSeconds, control.input, camera, jobs);
    EXPECT_TRUE(report.ok()) << report.status().message();
  }
  return {session->rgba().begin(), session->rgba().end()};
}

struct WindowRun {
  WindowRunResult result;
  bool ok = false;
};

WindowRun window_run(const InputScript& script, int frames) {
  WindowRun run;
  auto jobs = std::make_unique<JobSystem>(2);
  auto session = make_session(*jobs);
  if (!session) return run;
  auto window = Window::create({.width = kSize, .height = kSize, .title = "sinew demo test", .vsync = false,
                                .visible = true});
  EXPECT_TRUE(window.ok()) << window.status().message();
  if (!window.ok()) return run;
  WindowRunOptions options;
  options.frames = frames;
  options.script = &script;
  options.keep_last_shown = true;
  auto result = run_window(*session, jobs, **window, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  if (!result.ok()) return run;
  run.result = std::move(*result);
  run.ok = true;
  return run;
}

// Pixels of [x0, x1) x [y0, y1) whose RGB differs by more than 1 (the
// display's texture filtering may round).
int differing_pixels(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, int x0, int y0, int x1,
                     int y1) {
  int count = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::size_t i = static_cast<std::size_t>((y * kSize + x) * 4);
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int{a[i + static_cast<std::size_t>(c)]} - int{b[i + static_cast<std::size_t>(c)]}) > 1) {
          ++count;
          break;
        }
      }
    }
  }
  return count;
}

InputScript parse(const char* text) {
  auto script = InputScript::parse(text, "window_test");
  EXPECT_TRUE(script.ok()) << script.status().message();
  return script.ok() ? std::move(*script) : InputScript{};
}

TEST(DemoWindow, ShowsTheHeadlessFrameOnceF1HidesTheHud) {
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  // Walk, turn the camera, run, wave, hide the HUD.
  const InputScript script = parse(
      "0 w down\n6 e down\n14 e up\n16 shift down\n24 space tap\n26 f1 tap\n");
  constexpr int kFrames = 30;
  const WindowRun shown = window_run(script, kFrames);
  ASSERT_TRUE(shown.ok);
  EXPECT_EQ(shown.result.frames, kFrames);
  ASSERT_EQ(shown.result.shown_width, kSize);
  ASSERT_EQ(shown.result.shown_height, kSize);
  const auto expected = headless_frame(script, kFrames);
  ASSERT_EQ(expected.size(), shown.result.last_shown.size());
  EXPECT_EQ(differing_pixels(shown.result.last_shown, expected, 0, 0, kSize, kSize), 0);
  // And the frame is a scene, not a cleared window: the characters moved it
  // away from the first frame's picture.
  EXPECT_GT(differing_pixels(expected, headless_frame(script, 1), 0, 0, kSize, kSize), kSize * kSize / 50);
}

TEST(DemoWindow, TheHudCoversTheTopLeftAndNothingElse) {
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  const InputScript script = parse("0 w down\n");
  constexpr int kFrames = 4;
  const WindowRun shown = window_run(script, kFrames);
  ASSERT_TRUE(shown.ok);
  const auto expected = headless_frame(script, kFrames);
  ASSERT_EQ(expected.size(), shown.result.last_shown.size());
  // The HUD panel starts at (8, 8): its first lines of text are there.
  EXPECT_GT(differing_pixels(shown.result.last_shown, expected, 8, 8, 200, 60), 1000);
  // The panel is narrower than 400 pixels: the right edge shows the frame.
  EXPECT_EQ(differing_pixels(shown.result.last_shown, expected, 400, 0, kSize, kSize), 0);
}

TEST(DemoWindow, EscInTheScriptEndsTheRun) {
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  const InputScript script = parse("0 d down\n3 esc tap\n");
  const WindowRun shown = window_run(script, 100);
  ASSERT_TRUE(shown.ok);
  EXPECT_EQ(shown.result.frames, 3);  // frames 0, 1, 2; Esc on frame 3 quits before drawing it
}

}  // namespace
}  // namespace sinew::demo
