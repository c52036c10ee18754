// sinew-demo: the playable demo. Several skinned characters walk the arena,
// ray traced with shadows each frame; one is the player's. With a display
// it opens a window (keys below); without one, or with --headless, it runs
// a scripted, deterministic session and writes frames and timings.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "game_demo/demo_options.h"
#include "game_demo/demo_session.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/image/image_io.h"
#include "runtime/io/atomic_file.h"

#ifdef SINEW_HAVE_DISPLAY
#include <GLFW/glfw3.h>

#include "runtime/display/pixel_display.h"
#include "runtime/display/window.h"
#endif

namespace sinew::demo {
namespace {

constexpr float kFrameSeconds = 1.0f / 30.0f;  // the headless run's fixed step

std::string json_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", std::isfinite(v) ? v : 0.0);
  return text;
}

// Per-frame phase times, then the summary (per-phase medians and fps).
std::string timings_json(const std::vector<std::vector<std::pair<std::string, double>>>& rows,
                         const PhaseTimers& timers, const DemoSession& session, int threads,
                         std::uint64_t escaped_triangles) {
  std::string out = "{\n  \"frames\": [\n";
  for (std::size_t f = 0; f < rows.size(); ++f) {
    out += "    {\"frame\": " + std::to_string(f);
    for (const auto& [phase, ms] : rows[f]) out += ", \"" + phase + "\": " + json_number(ms);
    out += f + 1 < rows.size() ? "},\n" : "}\n";
  }
  const double total = timers.median_total_ms();
  const BakeInfo& bake = session.bake_info();
  out += "  ],\n  \"summary\": {\n";
  out += "    \"fps\": " + json_number(total > 0.0 ? 1000.0 / total : 0.0) + ",\n";
  out += "    \"frame_median_ms\": " + json_number(total) + ",\n";
  out += "    \"threads\": " + std::to_string(threads) + ",\n";
  out += "    \"characters\": " + std::to_string(session.world().character_count()) + ",\n";
  out += "    \"size\": [" + std::to_string(session.width()) + ", " + std::to_string(session.height()) + "],\n";
  out += "    \"model\": \"" + bake.model + "\",\n";
  out += "    \"triangles\": " + std::to_string(bake.triangles) + ",\n";
  out += "    \"pose_samples\": " + std::to_string(bake.pose_samples) + ",\n";
  out += "    \"escaped_triangles\": " + std::to_string(escaped_triangles) + ",\n";
  out += "    \"phases\": " + timers.json() + "  }\n}\n";
  return out;
}

int fail(const Status& s) {
  std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
  return 1;
}

int run_headless(const DemoOptions& opt, DemoSession& session, JobSystem& jobs) {
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
  for (int frame = 0; frame < opt.frames; ++frame) {
    const PlayerInput input = scripted_input(frame);
    camera.yaw = input.camera_yaw;
    auto report = session.frame(kFrameSeconds, input, camera, jobs);
    if (!report.ok()) return fail(report.status());
    escaped += report->scene.escaped_triangles;
    rows.push_back(session.timers().latest());
    // The first, middle and last frame: enough to see the characters move.
    if (frame == 0 || frame == opt.frames / 2 || frame == opt.frames - 1) {
      char name[64];
      std::snprintf(name, sizeof name, "/frame_%04d.png", frame);
      const std::string path = opt.out_dir + name;
      if (Status s = write_png(path, session.width(), session.height(), 4, session.rgba()); !s.ok()) return fail(s);
      written.push_back(path);
    }
  }
  const std::string timings_path = opt.out_dir + "/timings.json";
  if (Status s = write_file_atomic(timings_path, timings_json(rows, session.timers(), session, jobs.thread_count(), escaped));
      !s.ok()) {
    return fail(s);
  }
  const BakeInfo& bake = session.bake_info();
  std::printf("sinew-demo: %d characters (%s, %zu triangles, %u pose samples baked in %.0f ms), %d frames at %dx%d "
              "on %d threads (headless)\n",
              session.world().character_count(), bake.model.c_str(), bake.triangles, bake.pose_samples, bake.bake_ms,
              opt.frames, session.width(), session.height(), jobs.thread_count());
  std::printf("%s", session.timers().table().c_str());
  std::printf("fps (1000 / sum of phase medians): %.1f; escaped triangles over the run: %llu\n",
              1000.0 / session.timers().median_total_ms(), static_cast<unsigned long long>(escaped));
  std::printf("written:\n");
  for (const std::string& p : written) std::printf("  %s\n", p.c_str());
  std::printf("  %s\n", timings_path.c_str());
  return 0;
}

#ifdef SINEW_HAVE_DISPLAY
// Key state with press edges (Space and Tab act once per press).
class Keys {
 public:
  explicit Keys(const Window& window) : window_(window) {}
  bool down(int key) const { return window_.key_down(key); }
  bool pressed(int key) {
    const bool now = window_.key_down(key);
    const bool was = previous_[static_cast<std::size_t>(key)];
    previous_[static_cast<std::size_t>(key)] = now;
    return now && !was;
  }

 private:
  const Window& window_;
  std::vector<bool> previous_ = std::vector<bool>(GLFW_KEY_LAST + 1, false);
};

int run_windowed(const DemoOptions& opt, DemoSession& session, JobSystem& jobs) {
  WindowOptions wo;
  wo.width = opt.width;
  wo.height = opt.height;
  wo.title = "Sinew demo";
  auto window = Window::create(wo);
  if (!window.ok()) {
    std::fprintf(stderr, "sinew-demo: %s (try --headless)\n", window.status().message().c_str());
    return 1;
  }
  Window& win = **window;
  PixelDisplay display;
  Keys keys(win);
  FollowCamera camera;
  int frame = 0;
  auto last = std::chrono::steady_clock::now();
  while (!win.should_close() && (opt.frames == 0 || frame < opt.frames)) {
    win.poll_events();
    if (keys.down(GLFW_KEY_ESCAPE)) win.request_close();
    const auto now = std::chrono::steady_clock::now();
    const float dt = std::min(0.1f, std::chrono::duration<float>(now - last).count());
    last = now;
    PlayerInput input;
    input.forward = (keys.down(GLFW_KEY_W) || keys.down(GLFW_KEY_UP) ? 1.0f : 0.0f) -
                    (keys.down(GLFW_KEY_S) || keys.down(GLFW_KEY_DOWN) ? 1.0f : 0.0f);
    input.right = (keys.down(GLFW_KEY_D) || keys.down(GLFW_KEY_RIGHT) ? 1.0f : 0.0f) -
                  (keys.down(GLFW_KEY_A) || keys.down(GLFW_KEY_LEFT) ? 1.0f : 0.0f);
    input.run = keys.down(GLFW_KEY_LEFT_SHIFT) || keys.down(GLFW_KEY_RIGHT_SHIFT);
    input.action = keys.pressed(GLFW_KEY_SPACE);
    input.next_character = keys.pressed(GLFW_KEY_TAB);
    const float turn = (keys.down(GLFW_KEY_E) ? 1.0f : 0.0f) - (keys.down(GLFW_KEY_Q) ? 1.0f : 0.0f);
    camera.yaw += turn * 2.0f * dt;
    auto report = session.frame(dt, input, camera, jobs);
    if (!report.ok()) return fail(report.status());
    int vw = 0, vh = 0;
    win.framebuffer_size(&vw, &vh);
    {
      ScopedPhase phase(session.timers(), "display");
      if (Status s = display.present(session.width(), session.height(), session.rgba(), vw, vh); !s.ok()) return fail(s);
      win.swap_buffers();
    }
    ++frame;
  }
  std::printf("sinew-demo: %d frames\n%s", frame, session.timers().table().c_str());
  return 0;
}
#endif

int run(const std::vector<std::string>& args) {
  auto parsed = parse_demo_options(args);
  if (!parsed.ok()) {
    std::fprintf(stderr, "sinew-demo: %s\n%s", parsed.status().message().c_str(), demo_usage().c_str());
    return 2;
  }
  const DemoOptions& opt = *parsed;
  if (opt.help) {
    std::printf("%s", demo_usage().c_str());
    return 0;
  }
  if (Status s = check_cpu_supports_build(); !s.ok()) return fail(s);
  JobSystem jobs(opt.threads);
  SessionOptions so;
  so.model_path = opt.model_path;
  so.characters = opt.characters;
  so.seed = opt.seed;
  so.width = opt.width;
  so.height = opt.height;
  std::printf("sinew-demo: baking %s...\n", opt.model_path.empty() ? "the mannequin" : opt.model_path.c_str());
  std::fflush(stdout);
  auto session = DemoSession::create(so, jobs);
  if (!session.ok()) return fail(session.status());
#ifdef SINEW_HAVE_DISPLAY
  if (!opt.headless) {
    if (Window::display_available()) return run_windowed(opt, **session, jobs);
    std::printf("sinew-demo: no display available: running headless\n");
  }
#endif
  DemoOptions headless = opt;
  if (headless.frames == 0) headless.frames = 120;
  return run_headless(headless, **session, jobs);
}

}  // namespace
}  // namespace sinew::demo

int main(int argc, char** argv) {
  return sinew::demo::run(std::vector<std::string>(argv + 1, argv + argc));
}
