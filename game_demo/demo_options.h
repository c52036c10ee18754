// Command-line options of sinew-demo. Parsing never exits the process: it
// returns the options or a Status naming the bad flag, and main decides
// (exit code 2 for usage errors).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "game_demo/soft_lighting.h"
#include "raytrace/render/render_settings.h"
#include "runtime/core/expected.h"

namespace sinew::demo {

struct DemoOptions {
  bool headless = false;
  int frames = 0;  // 0: run until the window closes (windowed), 120 headless
  std::string out_dir = "out/demo";
  int threads = 0;  // 0: all cores
  int width = 1024;
  int height = 1024;
  std::uint32_t seed = 1;
  int characters = 6;
  float pace_spread = 0.0f;  // each character's own pace in [1 - s, 1 + s] (WorldOptions::pace_spread)
  std::string model_path;  // empty: the procedural mannequin
  std::string script_path;      // keys from this input script (input_script.h), fixed 1/30 s steps
  std::string screenshot_path;  // windowed: the last frame as shown, HUD included, as PNG
  bool hud = true;              // windowed: HUD shown at start
  std::vector<rt::Light> lights;  // empty: the arena's point light
  SoftLighting soft;              // --soft and its options: off by default
  bool help = false;
};

Expected<DemoOptions> parse_demo_options(const std::vector<std::string>& args);
std::string demo_usage();

}  // namespace sinew::demo
