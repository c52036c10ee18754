// sinew-demo: the playable demo. Several skinned characters walk the arena,
// ray traced with shadows each frame; one is the player's. With a display
// it opens a window (keys below); without one, or with --headless, it runs
// a scripted, deterministic session and writes frames and timings.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "game_demo/demo_options.h"
#include "game_demo/demo_session.h"
#include "game_demo/input_script.h"
#include "game_demo/timings_json.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/image/image_io.h"
#include "runtime/io/atomic_file.h"

#ifdef SINEW_HAVE_DISPLAY
#include "game_demo/window_loop.h"
#include "runtime/display/window.h"
#endif

namespace sinew::demo {
namespace {

int fail(const Status& s) {
  std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
  return 1;
}

int run_headless(const DemoOptions& opt, const InputScript* script, DemoSession& session, JobSystem& jobs) {
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "sinew-demo: %s: cannot create output folder: %s\n", opt.out_dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  std::vector<std::vector<std::pair<std::string, double>>> rows;
  std::vector<std::string> written;
  std::uint64_t escaped = 0;
  FollowCamera camera;
  auto write_frame = [&](int frame) -> Status {
    char name[64];
    std::snprintf(name, sizeof name, "/frame_%04d.png", frame);
    const std::string path = opt.out_dir + name;
    SINEW_RETURN_IF_ERROR(write_png(path, session.width(), session.height(), 4, session.rgba()));
    written.push_back(path);
    return Status();
  };
  int frames_run = 0;
  for (int frame = 0; frame < opt.frames; ++frame) {
    PlayerInput input;
    if (script != nullptr) {
      const ControlResult control = script_controls(*script, frame, camera);
      if (control.quit) break;  // the script pressed Esc
      input = control.input;
    } else {
      input = scripted_input(frame);
      camera.yaw = input.camera_yaw;
    }
    auto report = session.frame(kScriptStepSeconds, input, camera, jobs);
    if (!report.ok()) return fail(report.status());
    frames_run = frame + 1;
    escaped += report->scene.escaped_triangles;
    rows.push_back(session.timers().latest());
    // The first, middle and last frame: enough to see the characters move.
    if (frame == 0 || frame == opt.frames / 2) {
      if (Status s = write_frame(frame); !s.ok()) return fail(s);
    }
  }
  if (frames_run > 1 && frames_run - 1 != opt.frames / 2) {
    if (Status s = write_frame(frames_run - 1); !s.ok()) return fail(s);
  }
  const BakeInfo& bake = session.bake_info();
  TimingsRun run;
  run.frames = std::move(rows);
  run.timers = &session.timers();
  run.model = bake.model;
  run.triangles = bake.triangles;
  run.pose_samples = bake.pose_samples;
  run.characters = session.world().character_count();
  run.width = session.width();
  run.height = session.height();
  run.threads = jobs.thread_count();
  run.escaped_triangles = escaped;
  const std::string timings_path = opt.out_dir + "/timings.json";
  if (Status s = write_file_atomic(timings_path, timings_json(run)); !s.ok()) return fail(s);
  std::printf("sinew-demo: %d characters (%s, %zu triangles, %u pose samples baked in %.0f ms), %d frames at %dx%d "
              "on %d threads (headless)\n",
              session.world().character_count(), bake.model.c_str(), bake.triangles, bake.pose_samples, bake.bake_ms,
              frames_run, session.width(), session.height(), jobs.thread_count());
  if (const SoftLighting& soft = session.soft_lighting(); soft.light_radius > 0.0f || soft.ao_rays > 0) {
    std::printf("soft lighting: light radius %.2f m, %d shadow samples; %d ambient occlusion rays of %.2f m\n",
                static_cast<double>(soft.light_radius), soft.shadow_samples, soft.ao_rays,
                static_cast<double>(soft.ao_radius));
  }
  std::printf("%s", session.timers().table().c_str());
  std::printf("fps (1000 / sum of phase medians): %.1f; escaped triangles over the run: %llu\n",
              1000.0 / session.timers().median_total_ms(), static_cast<unsigned long long>(escaped));
  std::printf("written:\n");
  for (const std::string& p : written) std::printf("  %s\n", p.c_str());
  std::printf("  %s\n", timings_path.c_str());
  return 0;
}

#ifdef SINEW_HAVE_DISPLAY
int run_windowed(const DemoOptions& opt, const InputScript* script, DemoSession& session,
                 std::unique_ptr<JobSystem>& jobs) {
  WindowOptions wo;
  wo.width = opt.width;
  wo.height = opt.height;
  wo.title = "Sinew demo";
  auto window = Window::create(wo);
  if (!window.ok()) {
    std::fprintf(stderr, "sinew-demo: %s (try --headless)\n", window.status().message().c_str());
    return 1;
  }
  WindowRunOptions run;
  run.frames = opt.frames;
  run.script = script;
  run.hud = opt.hud;
  run.keep_last_shown = !opt.screenshot_path.empty();
  auto result = run_window(session, jobs, **window, run);
  if (!result.ok()) return fail(result.status());
  std::printf("sinew-demo: %d frames\n%s", result->frames, session.timers().table().c_str());
  if (!opt.screenshot_path.empty()) {
    if (result->last_shown.empty()) {
      std::fprintf(stderr, "sinew-demo: %s: no frame was shown, so there is no screenshot\n",
                   opt.screenshot_path.c_str());
      return 1;
    }
    if (Status s = write_png(opt.screenshot_path, result->shown_width, result->shown_height, 4, result->last_shown);
        !s.ok()) {
      return fail(s);
    }
    std::printf("screenshot: %s\n", opt.screenshot_path.c_str());
  }
  return 0;
}
#endif

int run(const std::vector<std::string>& args) {
  auto parsed = parse_demo_options(args);
  if (!parsed.ok()) {
    std::fprintf(stderr, "sinew-demo: %s\n", parsed.status().message().c_str());
    return 2;
  }
  const DemoOptions& opt = *parsed;
  if (opt.help) {
    std::printf("%s", demo_usage().c_str());
    return 0;
  }
  if (Status s = check_cpu_supports_build(); !s.ok()) return fail(s);
  std::optional<InputScript> script;
  if (!opt.script_path.empty()) {
    auto loaded = InputScript::load(opt.script_path);
    if (!loaded.ok()) return fail(loaded.status());
    script = std::move(*loaded);
  }
  const InputScript* script_ptr = script ? &*script : nullptr;
  auto jobs = std::make_unique<JobSystem>(opt.threads);
  SessionOptions so;
  so.model_path = opt.model_path;
  so.characters = opt.characters;
  so.seed = opt.seed;
  so.pace_spread = opt.pace_spread;
  so.width = opt.width;
  so.height = opt.height;
  so.lights = opt.lights;
  so.soft = opt.soft;
  std::printf("sinew-demo: loading %s...\n", opt.model_path.empty() ? "the mannequin" : opt.model_path.c_str());
  std::fflush(stdout);
  auto session = DemoSession::create(so, *jobs);
  if (!session.ok()) return fail(session.status());
#ifdef SINEW_HAVE_DISPLAY
  if (!opt.headless) {
    if (Window::display_available()) return run_windowed(opt, script_ptr, **session, jobs);
    std::printf("sinew-demo: no display available: running headless\n");
  }
#endif
  DemoOptions headless = opt;
  if (headless.frames == 0) headless.frames = 120;
  return run_headless(headless, script_ptr, **session, *jobs);
}

}  // namespace
}  // namespace sinew::demo

int main(int argc, char** argv) {
  return sinew::demo::run(std::vector<std::string>(argv + 1, argv + argc));
}
