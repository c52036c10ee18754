// The editor window, `sinew-editor gui [MODEL|PACK]`: GLFW + Dear ImGui
// panels (load, clips, bake, joint limits, overlays, stats) beside the
// ray-traced viewport, shown through the pixel display.
//
//   sinew-editor gui [MODEL|PACK] [--size WxH] [--frames N] [--screenshot PATH]
//       [--overlay none|boxes|heat|escapes] [--bone NAME|INDEX] [--clip NAME]
//       [--time S] [--threads N]
//
// Layout: the viewport fills the window's left part at 1:1 pixels (the
// render is the viewport's size), the panels a fixed column on the right,
// so a screenshot's viewport region is exactly the overlaid render.
// A baked pack renders from its own fuzzy trees; any other model is baked
// in memory with the default pose space (every clip) when it loads.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "animation/pose_space.h"
#include "character/model.h"
#include "editor/gui/overlays.h"
#include "editor/gui/viewport.h"
#include "editor/gui/widget_log.h"
#include "runtime/core/expected.h"

namespace sinew::editor::gui {

struct GuiOptions {
  std::string model_path;  // empty: start without a model
  int width = 1024;        // the window
  int height = 768;
  int frames = 0;          // 0: run until the window closes
  std::string screenshot;  // PNG of the last frame shown
  Overlay overlay = Overlay::kNone;
  std::string bone;  // name or index (boxes overlay); empty: the first bone with triangles
  std::string clip;  // clip A; empty: the first clip
  std::optional<double> time;  // playback time; given: starts paused there
  int threads = 0;             // render threads, 0: all cores
  std::string pack_path = "/tmp/editor.pack";            // the panel's first "Save as pack" target
  std::string limits_path = "/tmp/editor_limits.json";  // and "Save limits" target
  bool visible = true;
  bool help = false;
};

// Errors name the flag and the value (usage errors, exit code 2).
Expected<GuiOptions> parse_gui_options(const std::vector<std::string>& args);
std::string gui_usage();

// The bake panel's settings.
struct BakeSettings {
  anim::PoseSpaceMode mode = anim::PoseSpaceMode::kClips;
  std::string clip;   // kClip
  int samples = 0;    // kArbitrary/kLimits: poses (0 -> 1000); clip modes: 0 = every key time
  float padding = 0.0f;
  bool every_frame_30hz = true;  // clip modes
};

struct EditorStats {
  double fps = 0.0;
  std::vector<std::pair<std::string, double>> phases_ms;  // last frame
  std::size_t triangles = 0;
  std::size_t bones = 0;
  std::uint32_t pose_samples = 0;
  double fuzzy_area_ratio = 0.0;  // fuzzy_area / rest_area of the trees in use
  std::size_t escaped_triangles = 0;  // this frame
  std::size_t escaped_pixels = 0;     // painted by the escapes overlay this frame
  // This frame's shadow and ambient occlusion rays, and their share of the
  // render's time (rt::RenderStats).
  std::uint64_t shadow_rays = 0;
  std::uint64_t ao_rays = 0;
  double trace_shadow_ms = 0.0;
  double trace_ao_ms = 0.0;
  bool from_pack = false;             // the trees in use came from a pack
};

struct Screenshot {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // row 0 on top
};

class EditorApp {
 public:
  // Opens the window (kIoError without a display) and loads
  // options.model_path when given.
  static Expected<std::unique_ptr<EditorApp>> create(const GuiOptions& options);
  ~EditorApp();
  EditorApp(const EditorApp&) = delete;
  EditorApp& operator=(const EditorApp&) = delete;

  // Replaces the model (a running bake is cancelled first).
  Status load(const std::string& path);
  Status load(character::Model model);

  // One frame: input, animation, bake polling, render, overlay, panels,
  // swap. False once the window was asked to close.
  Expected<bool> step();

  void set_overlay(Overlay overlay);
  Status set_bone(const std::string& name_or_index);
  Status set_clip(const std::string& name);  // clip A alone
  Status set_cycles(int clip_a, int clip_b, float blend);
  Status set_time(double seconds);
  void set_playing(bool playing);
  Status trigger_action(int clip);
  void orbit(float yaw_radians, float pitch_radians);

  // Starts a bake on a worker thread; the viewport switches to the new
  // trees in the step() that sees it finish. kInvalidArgument while one runs.
  Status start_bake(const BakeSettings& settings);
  bool bake_running() const;
  double bake_progress() const;
  void cancel_bake();
  // The last load/bake/save message ("" when none), e.g. the cancel notice.
  const std::string& message() const;

  // Read the back buffer every frame into last_shown() (off by default:
  // it costs a GPU round trip).
  void set_capture(bool on);
  const Screenshot& last_shown() const;

  // Every panel widget the last frame drew, in window pixels, and the
  // window's top-left corner on the screen: where a test moves the real
  // pointer to click one.
  const WidgetLog& widgets() const;
  void window_position(int* x, int* y) const;

  const character::Model* model() const;
  rt::FuzzyCharacterView fuzzy() const;
  std::span<const Affine3> skinning() const;  // of the last frame
  const Viewport& viewport() const;
  Viewport& viewport();
  EditorStats stats() const;

 private:
  struct Impl;
  explicit EditorApp(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The subcommand: arguments after "gui". Returns 0 success, 1 user error
// (missing model, no display), 2 usage error; `--help` prints the usage.
int run_gui(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sinew::editor::gui

namespace sinew::editor {
using gui::run_gui;  // where the lead wires `sinew-editor gui`
}  // namespace sinew::editor
