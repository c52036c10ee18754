// sinew-demo: the playable demo's entry point.
//
// This increment renders the arena (ground, obstacles, one light with
// shadows) through the runtime's job system, timers, image output and, when
// a display is present, the PBO display path. Skinned characters join when
// the animation and ray-tracing subsystems land (issues 3, 4 and 6).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "game_demo/arena.h"
#include "game_demo/demo_options.h"
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

// The scripted camera: one orbit of the arena every 8 seconds at 30 fps.
Camera orbit_camera(int frame) {
  const float angle = 2.0f * 3.14159265f * float(frame) / 240.0f;
  Camera c;
  c.eye = Vec3(14.0f * std::cos(angle), 6.0f, 14.0f * std::sin(angle));
  c.target = Vec3(0.0f, 0.5f, 0.0f);
  return c;
}

std::string timings_json(const PhaseTimers& timers, int frames, int threads, int w, int h) {
  const double total = timers.median_total_ms();
  char head[256];
  std::snprintf(head, sizeof head,
                "{\n  \"frames\": %d,\n  \"threads\": %d,\n  \"size\": [%d, %d],\n"
                "  \"summary\": {\"fps\": %.3f, \"frame_median_ms\": %.4f, \"phases\": ",
                frames, threads, w, h, total > 0 ? 1000.0 / total : 0.0, total);
  return std::string(head) + timers.json() + "}\n}\n";
}

int run_headless(const DemoOptions& opt, const Arena& arena, JobSystem& jobs) {
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "sinew-demo: %s: cannot create output folder: %s\n", opt.out_dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  FrameBuffers fb;
  fb.resize(opt.width, opt.height);
  PhaseTimers timers;
  std::vector<std::string> written;
  for (int frame = 0; frame < opt.frames; ++frame) {
    render_arena(arena, orbit_camera(frame), jobs, fb, timers);
    // Keep the first, middle and last frame: enough to see motion.
    if (frame == 0 || frame == opt.frames / 2 || frame == opt.frames - 1) {
      char name[64];
      std::snprintf(name, sizeof name, "/frame_%04d.png", frame);
      const std::string path = opt.out_dir + name;
      if (Status s = write_png(path, fb.width, fb.height, 4, fb.rgba); !s.ok()) {
        std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
        return 1;
      }
      written.push_back(path);
    }
  }
  const std::string timings_path = opt.out_dir + "/timings.json";
  if (Status s = write_file_atomic(timings_path,
                                   timings_json(timers, opt.frames, jobs.thread_count(), fb.width, fb.height));
      !s.ok()) {
    std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("sinew-demo: rendered %d frames of the arena at %dx%d on %d threads (headless)\n",
              opt.frames, fb.width, fb.height, jobs.thread_count());
  std::printf("%s", timers.table().c_str());
  std::printf("fps (1000 / sum of phase medians): %.1f\n", 1000.0 / timers.median_total_ms());
  std::printf("frames written:\n");
  for (const std::string& p : written) std::printf("  %s\n", p.c_str());
  std::printf("  %s\n", timings_path.c_str());
  std::printf("characters join the arena with the animation and ray-tracer issues.\n");
  return 0;
}

#ifdef SINEW_HAVE_DISPLAY
int run_windowed(const DemoOptions& opt, const Arena& arena, JobSystem& jobs) {
  WindowOptions wo;
  wo.width = opt.width;
  wo.height = opt.height;
  wo.title = "Sinew demo";
  auto window = Window::create(wo);
  if (!window.ok()) {
    std::fprintf(stderr, "sinew-demo: %s (try --headless)\n", window.status().message().c_str());
    return 1;
  }
  PixelDisplay display;
  FrameBuffers fb;
  fb.resize(opt.width, opt.height);
  PhaseTimers timers;
  int frame = 0;
  while (!(*window)->should_close() && (opt.frames == 0 || frame < opt.frames)) {
    (*window)->poll_events();
    if ((*window)->key_down(GLFW_KEY_ESCAPE)) (*window)->request_close();
    render_arena(arena, orbit_camera(frame), jobs, fb, timers);
    int vw = 0, vh = 0;
    (*window)->framebuffer_size(&vw, &vh);
    {
      ScopedPhase phase(timers, "display");
      if (Status s = display.present(fb.width, fb.height, fb.rgba, vw, vh); !s.ok()) {
        std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
        return 1;
      }
      (*window)->swap_buffers();
    }
    ++frame;
  }
  std::printf("sinew-demo: %d frames\n%s", frame, timers.table().c_str());
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
  if (Status s = check_cpu_supports_build(); !s.ok()) {
    std::fprintf(stderr, "sinew-demo: %s\n", s.message().c_str());
    return 1;
  }
  JobSystem jobs(opt.threads);
  const Arena arena = Arena::generate(opt.seed, 8);
#ifdef SINEW_HAVE_DISPLAY
  if (!opt.headless) {
    if (Window::display_available()) return run_windowed(opt, arena, jobs);
    std::printf("sinew-demo: no display available: running headless\n");
  }
#endif
  DemoOptions headless = opt;
  if (headless.frames == 0) headless.frames = 120;
  return run_headless(headless, arena, jobs);
}

}  // namespace
}  // namespace sinew::demo

int main(int argc, char** argv) {
  return sinew::demo::run(std::vector<std::string>(argv + 1, argv + argc));
}
