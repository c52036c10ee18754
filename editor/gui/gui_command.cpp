// `sinew-editor gui`: argument parsing and the automation loop (frames,
// screenshot) around EditorApp.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "editor/gui/editor_app.h"
#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "runtime/image/image_io.h"

namespace sinew::editor::gui {
namespace {

constexpr int kMinWidth = 320;
constexpr int kMinHeight = 200;

struct GuiFlags {
  explicit GuiFlags(cli::CommandLine& l)
      : model(l.positionals("MODEL", "the model or pack to open (.gltf, .glb, .cfg, .pack)", 1)),
        size(l.option("--size", "WxH", "window size (default 1024x768; at least 320x200)")),
        frames(l.option("--frames", "N", "quit after N frames (0: run until closed)")),
        screenshot(l.option("--screenshot", "PATH", "write the last frame shown as PNG")),
        overlay(l.option("--overlay", "none|boxes|heat|escapes",
                         "viewport overlay: fuzzy boxes of a bone, leaf-size heat map,\n"
                         "escaped triangles in red")),
        bone(l.option("--bone", "NAME|INDEX", "the bone of the boxes overlay")),
        clip(l.option("--clip", "NAME", "the clip to play (name or #index)")),
        time(l.option("--time", "S", "playback time in seconds; starts paused there")),
        threads(l.option("--threads", "N", "render threads (default 0: all cores)")) {}

  const std::vector<std::string>& model;
  const std::optional<std::string>& size;
  const std::optional<std::string>& frames;
  const std::optional<std::string>& screenshot;
  const std::optional<std::string>& overlay;
  const std::optional<std::string>& bone;
  const std::optional<std::string>& clip;
  const std::optional<std::string>& time;
  const std::optional<std::string>& threads;
};

const char* const kDescription = "Opens the editor window on MODEL (.gltf, .glb, .cfg, .pack).\n";

}  // namespace

std::string gui_usage() {
  cli::CommandLine line("sinew-editor gui", kDescription);
  const GuiFlags flags(line);
  return line.help();
}

Expected<GuiOptions> parse_gui_options(const std::vector<std::string>& args) {
  cli::CommandLine line("sinew-editor gui", kDescription);
  const GuiFlags f(line);
  SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, line.parse(args));
  GuiOptions options;
  if (result == cli::ParseResult::kHelp) {
    options.help = true;
    return options;
  }
  if (!f.model.empty()) options.model_path = f.model.front();
  if (f.size) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--size", *f.size, 16384, kMinHeight));
    if (size.width < kMinWidth) return invalid_argument("--size", *f.size, "expected at least 320x200");
    options.width = size.width;
    options.height = size.height;
  }
  if (f.frames) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--frames", *f.frames, 0, 1000000000));
    options.frames = static_cast<int>(n);
  }
  if (f.screenshot) options.screenshot = *f.screenshot;
  if (f.overlay) {
    SINEW_ASSIGN_OR_RETURN(options.overlay, parse_overlay(*f.overlay));
  }
  if (f.bone) options.bone = *f.bone;
  if (f.clip) options.clip = *f.clip;
  if (f.time) {
    SINEW_ASSIGN_OR_RETURN(const double seconds, cli::parse_double("--time", *f.time, 0.0, 1e9));
    options.time = seconds;
  }
  if (f.threads) {
    SINEW_ASSIGN_OR_RETURN(options.threads, cli::parse_threads("--threads", *f.threads));
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
    return cli::usage_error("sinew-editor gui", options.status(), err);
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
