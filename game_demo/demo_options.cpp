#include "game_demo/demo_options.h"

#include <cstdint>
#include <limits>
#include <type_traits>
#include <optional>

#include "character/framing.h"
#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"

namespace sinew::demo {
namespace {

// The options, declared in the order --help lists them.
struct DemoFlags {
  explicit DemoFlags(cli::CommandLine& l)
      : headless(l.flag("--headless", "no window: a scripted, deterministic run writing frames to DIR")),
        frames(l.option("--frames", "N", "frames to run (headless default 120; windowed: until Esc)")),
        out(l.option("--out", "DIR", "where headless frames and timings.json go (default out/demo)")),
        threads(l.option("--threads", "N", "worker threads (default 0: all cores)")),
        size(l.option("--size", "WxH", "frame size (default 1024x1024; 16 to 8192 each)")),
        seed(l.option("--seed", "S", "seed of the arena and the characters' wandering (default 1)")),
        characters(l.option("--characters", "N", "characters in the arena, one of them yours (default 6)")),
        pace_spread(l.option("--pace-spread", "S",
                             "each character but yours walks, runs and plays its cycles at its own\n"
                             "pace, drawn from [1 - S, 1 + S]; 0 to 0.5 (default 0: all alike)")),
        model(l.option("--model", "PATH",
                       "the character: a content pack (sinew-editor bake MODEL -o PATH);\n"
                       "default the procedural mannequin")),
        script(l.option("--script", "FILE",
                        "take the keys from an input script (frame key down|up|tap per\n"
                        "line) with fixed 1/30 s steps, windowed or headless")),
        screenshot(l.option("--screenshot", "PATH", "windowed: write the last frame as shown (HUD included) as PNG")),
        no_hud(l.flag("--no-hud", "windowed: start with the HUD hidden (F1 shows it)")),
        lights(l.repeated_option("--light", "X,Y,Z|point:X,Y,Z|dir:X,Y,Z[:R,G,B]",
                                 "a point light at X,Y,Z or a directional light towards X,Y,Z, with\n"
                                 "its linear colour (default 1,1,1); up to 8 (default: the arena's\n"
                                 "point light)")),
        soft(l) {}

  const bool& headless;
  const std::optional<std::string>& frames;
  const std::optional<std::string>& out;
  const std::optional<std::string>& threads;
  const std::optional<std::string>& size;
  const std::optional<std::string>& seed;
  const std::optional<std::string>& characters;
  const std::optional<std::string>& pace_spread;
  const std::optional<std::string>& model;
  const std::optional<std::string>& script;
  const std::optional<std::string>& screenshot;
  const bool& no_hud;
  const std::vector<std::string>& lights;
  SoftLightingFlags soft;
};

const char* const kDescription =
    "The playable demo: skinned characters walk the arena, ray traced with shadows each frame.\n"
    "With a display it opens a window; without one, or with --headless, it runs a scripted,\n"
    "deterministic session and writes frames and timings.\n";

}  // namespace

std::string demo_usage() {
  cli::CommandLine line("sinew-demo", kDescription);
  const DemoFlags flags(line);
  return line.help();
}

Expected<DemoOptions> parse_demo_options(const std::vector<std::string>& args) {
  cli::CommandLine line("sinew-demo", kDescription);
  const DemoFlags f(line);
  SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, line.parse(args));
  DemoOptions o;
  if (result == cli::ParseResult::kHelp) {
    o.help = true;
    return o;
  }
  o.headless = f.headless;
  o.hud = !f.no_hud;
  const auto int_option = [](const char* flag, const std::optional<std::string>& text, std::int64_t lo,
                             std::int64_t hi, auto& target) -> Status {
    if (text) {
      SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int(flag, *text, lo, hi));
      target = static_cast<std::remove_reference_t<decltype(target)>>(n);
    }
    return {};
  };
  SINEW_RETURN_IF_ERROR(int_option("--frames", f.frames, 1, 1000000, o.frames));
  SINEW_RETURN_IF_ERROR(int_option("--seed", f.seed, 0, std::numeric_limits<std::uint32_t>::max(), o.seed));
  SINEW_RETURN_IF_ERROR(int_option("--characters", f.characters, 1, 256, o.characters));
  if (f.pace_spread) {
    SINEW_ASSIGN_OR_RETURN(const double spread, cli::parse_double("--pace-spread", *f.pace_spread, 0.0, 0.5));
    o.pace_spread = static_cast<float>(spread);
  }
  if (f.threads) {
    SINEW_ASSIGN_OR_RETURN(o.threads, cli::parse_threads("--threads", *f.threads));
  }
  if (f.size) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--size", *f.size, 8192, 16));
    o.width = size.width;
    o.height = size.height;
  }
  if (f.out) o.out_dir = *f.out;
  if (f.model) o.model_path = *f.model;
  if (f.script) o.script_path = *f.script;
  if (f.screenshot) o.screenshot_path = *f.screenshot;
  if (f.lights.size() > rt::kMaxLights) {
    return invalid_argument("--light", f.lights.back(),
                            "at most " + std::to_string(rt::kMaxLights) + " lights");
  }
  for (const std::string& text : f.lights) {
    SINEW_ASSIGN_OR_RETURN(const cli::LightOption light, cli::parse_light("--light", text));
    o.lights.push_back(character::light_from_option(light));
  }
  SINEW_ASSIGN_OR_RETURN(o.soft, f.soft.parse());
  if (o.headless && o.frames == 0) o.frames = 120;
  return o;
}

}  // namespace sinew::demo
