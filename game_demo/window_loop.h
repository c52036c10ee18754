// The windowed game loop: keyboard (or an input script) -> world -> ray
// traced frame -> pixel display -> HUD. Lives in the display-only part of
// the demo so headless builds never link GLFW, GL or ImGui.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "game_demo/demo_session.h"
#include "game_demo/input_script.h"
#include "runtime/core/expected.h"
#include "runtime/display/window.h"
#include "runtime/jobs/job_system.h"

namespace sinew::demo {

struct WindowRunOptions {
  int frames = 0;  // 0: until Esc or the window closes
  // Keys come from this script, with fixed 1/30 s steps, instead of the
  // keyboard and the clock: the run is then the same as a headless run of
  // the same script, frame for frame.
  const InputScript* script = nullptr;
  bool hud = true;  // shown at start (F1 toggles)
  // Keep a copy of the last frame as shown, HUD included (read back from
  // the back buffer before every swap: for tests and --screenshot).
  bool keep_last_shown = false;
};

struct WindowRunResult {
  int frames = 0;
  std::vector<std::uint8_t> last_shown;  // RGBA8, row 0 on top; when kept
  int shown_width = 0;
  int shown_height = 0;
};

// Runs the loop in `window` (whose GL context is current). `jobs` may be
// replaced when the player changes the thread count in the HUD.
Expected<WindowRunResult> run_window(DemoSession& session, std::unique_ptr<JobSystem>& jobs, Window& window,
                                     const WindowRunOptions& options);

}  // namespace sinew::demo
