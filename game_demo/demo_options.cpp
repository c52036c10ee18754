#include "game_demo/demo_options.h"

#include <charconv>
#include <limits>

namespace sinew::demo {
namespace {

template <typename T>
Expected<T> parse_number(const std::string& flag, const std::string& text, T lo, T hi) {
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi) {
    return invalid_argument(flag, text,
                            "expected an integer from " + std::to_string(lo) + " to " +
                                std::to_string(hi));
  }
  return value;
}

}  // namespace

std::string demo_usage() {
  return "usage: sinew-demo [--headless] [--frames N] [--out DIR] [--threads N]\n"
         "                  [--size WxH] [--seed S] [--characters N] [--model PATH]\n"
         "                  [--script FILE] [--screenshot PATH] [--no-hud]\n"
         "  --headless      no window: a scripted, deterministic run writing frames to DIR\n"
         "  --frames N      frames to run (headless default 120; windowed: until Esc)\n"
         "  --out DIR       where headless frames and timings.json go (default out/demo)\n"
         "  --threads N     worker threads (default: all cores)\n"
         "  --size WxH      frame size (default 1024x1024)\n"
         "  --seed S        seed of the arena and the characters' wandering (default 1)\n"
         "  --characters N  characters in the arena, one of them yours (default 6)\n"
         "  --model PATH    the character: a content pack (sinew-editor bake MODEL -o PATH);\n"
         "                  default the procedural mannequin\n"
         "  --script FILE   take the keys from an input script (frame key down|up|tap per\n"
         "                  line) with fixed 1/30 s steps, windowed or headless\n"
         "  --screenshot PATH  windowed: write the last frame as shown (HUD included) as PNG\n"
         "  --no-hud        windowed: start with the HUD hidden (F1 shows it)\n";
}

Expected<DemoOptions> parse_demo_options(const std::vector<std::string>& args) {
  DemoOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto next = [&]() -> Expected<std::string> {
      if (i + 1 >= args.size()) return invalid_argument(a, "", "missing value");
      return args[++i];
    };
    if (a == "--headless") {
      o.headless = true;
    } else if (a == "--help" || a == "-h") {
      o.help = true;
    } else if (a == "--frames") {
      SINEW_ASSIGN_OR_RETURN(std::string v, next());
      SINEW_ASSIGN_OR_RETURN(o.frames, parse_number<int>(a, v, 1, 1000000));
    } else if (a == "--threads") {
      SINEW_ASSIGN_OR_RETURN(std::string v, next());
      SINEW_ASSIGN_OR_RETURN(o.threads, parse_number<int>(a, v, 1, 1024));
    } else if (a == "--seed") {
      SINEW_ASSIGN_OR_RETURN(std::string v, next());
      SINEW_ASSIGN_OR_RETURN(o.seed, parse_number<std::uint32_t>(
                                          a, v, 0, std::numeric_limits<std::uint32_t>::max()));
    } else if (a == "--characters") {
      SINEW_ASSIGN_OR_RETURN(std::string v, next());
      SINEW_ASSIGN_OR_RETURN(o.characters, parse_number<int>(a, v, 1, 256));
    } else if (a == "--model") {
      SINEW_ASSIGN_OR_RETURN(o.model_path, next());
    } else if (a == "--script") {
      SINEW_ASSIGN_OR_RETURN(o.script_path, next());
    } else if (a == "--screenshot") {
      SINEW_ASSIGN_OR_RETURN(o.screenshot_path, next());
    } else if (a == "--no-hud") {
      o.hud = false;
    } else if (a == "--out") {
      SINEW_ASSIGN_OR_RETURN(o.out_dir, next());
    } else if (a == "--size") {
      SINEW_ASSIGN_OR_RETURN(std::string v, next());
      const auto x = v.find('x');
      if (x == std::string::npos) return invalid_argument(a, v, "expected WxH, e.g. 1024x1024");
      SINEW_ASSIGN_OR_RETURN(o.width, parse_number<int>(a, v.substr(0, x), 16, 8192));
      SINEW_ASSIGN_OR_RETURN(o.height, parse_number<int>(a, v.substr(x + 1), 16, 8192));
    } else {
      return invalid_argument("argument", a, "unknown option (see --help)");
    }
  }
  if (o.headless && o.frames == 0) o.frames = 120;
  return o;
}

}  // namespace sinew::demo
