// `sinew-editor gui`: argument parsing and the automation loop (frames,
// screenshot) around EditorApp.
#include <charconv>
#include <cmath>
#include <string_view>

#include "editor/gui/editor_app.h"
#include "runtime/image/image_io.h"

namespace sinew::editor::gui {
namespace {

Expected<int> parse_int(std::string_view flag, std::string_view text, int min_value) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value < min_value) {
    return invalid_argument(flag, std::string(text), "expected an integer >= " + std::to_string(min_value));
  }
  return value;
}

Expected<double> parse_seconds(std::string_view flag, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value) || value < 0.0) {
    return invalid_argument(flag, text, "expected a finite number of seconds >= 0");
  }
  return value;
}

Status parse_size(const std::string& text, GuiOptions& options) {
  const std::size_t x = text.find('x');
  if (x == std::string::npos) return invalid_argument("--size", text, "expected WxH");
  SINEW_ASSIGN_OR_RETURN(options.width, parse_int("--size", std::string_view(text).substr(0, x), 320));
  SINEW_ASSIGN_OR_RETURN(options.height, parse_int("--size", std::string_view(text).substr(x + 1), 200));
  return Status{};
}

}  // namespace

std::string gui_usage() {
  return "usage: sinew-editor gui [MODEL|PACK] [--size WxH] [--frames N] [--screenshot PATH]\n"
         "           [--overlay none|boxes|heat|escapes] [--bone NAME|INDEX] [--clip NAME]\n"
         "           [--time S] [--threads N]\n"
         "Opens the editor window on MODEL (.gltf, .glb, .cfg, .pack).\n"
         "  --size WxH        window size (default 1024x768; at least 320x200)\n"
         "  --frames N        quit after N frames (0: run until closed)\n"
         "  --screenshot PATH write the last frame shown as PNG\n"
         "  --overlay MODE    viewport overlay: fuzzy boxes of a bone, leaf-size heat map,\n"
         "                    escaped triangles in red\n"
         "  --bone NAME|INDEX the bone of the boxes overlay\n"
         "  --clip NAME       the clip to play (name or #index)\n"
         "  --time S          playback time in seconds; starts paused there\n"
         "  --threads N       render threads (0: all cores)\n";
}

Expected<GuiOptions> parse_gui_options(const std::vector<std::string>& args) {
  GuiOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      options.help = true;
      continue;
    }
    if (arg.rfind("--", 0) != 0) {
      if (!options.model_path.empty()) return invalid_argument("MODEL", arg, "only one model may be given");
      options.model_path = arg;
      continue;
    }
    if (i + 1 >= args.size()) return invalid_argument(arg, "", "needs a value");
    const std::string& value = args[++i];
    if (arg == "--size") {
      SINEW_RETURN_IF_ERROR(parse_size(value, options));
    } else if (arg == "--frames") {
      SINEW_ASSIGN_OR_RETURN(options.frames, parse_int(arg, value, 0));
    } else if (arg == "--screenshot") {
      options.screenshot = value;
    } else if (arg == "--overlay") {
      SINEW_ASSIGN_OR_RETURN(options.overlay, parse_overlay(value));
    } else if (arg == "--bone") {
      options.bone = value;
    } else if (arg == "--clip") {
      options.clip = value;
    } else if (arg == "--time") {
      SINEW_ASSIGN_OR_RETURN(const double seconds, parse_seconds(arg, value));
      options.time = seconds;
    } else if (arg == "--threads") {
      SINEW_ASSIGN_OR_RETURN(options.threads, parse_int(arg, value, 0));
    } else {
      return invalid_argument("flag", arg, "unknown option (see --help)");
    }
  }
  if (!options.screenshot.empty() && options.frames == 0) options.frames = 1;
  return options;
}

namespace {

Status run_loop(const GuiOptions& options) {
  SINEW_ASSIGN_OR_RETURN(std::unique_ptr<EditorApp> app, EditorApp::create(options));
  const bool screenshot = !options.screenshot.empty();
  for (int frame = 0; options.frames == 0 || frame < options.frames; ++frame) {
    // Only the last frame is read back: it is the one written.
    app->set_capture(screenshot && frame + 1 == options.frames);
    SINEW_ASSIGN_OR_RETURN(const bool open, app->step());
    if (!open) break;
  }
  if (screenshot) {
    const Screenshot& shot = app->last_shown();
    if (shot.rgba.empty()) {
      return make_error(ErrorCode::kIoError, options.screenshot, "screenshot", "none",
                        "the window closed before a frame was shown");
    }
    SINEW_RETURN_IF_ERROR(write_png(options.screenshot, shot.width, shot.height, 4, shot.rgba));
  }
  return Status{};
}

}  // namespace

int run_gui(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  Expected<GuiOptions> options = parse_gui_options(args);
  if (!options.ok()) {
    err << "sinew-editor gui: " << options.status().message() << "\n" << gui_usage();
    return 2;
  }
  if (options->help) {
    out << gui_usage();
    return 0;
  }
  const Status status = run_loop(*options);
  if (!status.ok()) {
    err << "sinew-editor gui: " << status.message() << "\n";
    return 1;
  }
  if (!options->screenshot.empty()) out << "wrote " << options->screenshot << "\n";
  return 0;
}

}  // namespace sinew::editor::gui
