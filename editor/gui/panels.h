// The editor's ImGui panels, in one fixed column right of the viewport:
// model, clips, overlay, lights, bake, joint limits, stats. Drawing returns the
// actions the user asked for; EditorApp carries them out (loading and
// baking touch state the panels do not own). Each widget has its own ImGui
// ID: a label shared inside the window gets a "##" suffix (see
// widget_log.h for the test that walks them).
#pragma once

#include <array>
#include <span>
#include <string>

#include "animation/joint_limits.h"
#include "editor/gui/editor_app.h"
#include "editor/gui/pose_player.h"
#include "editor/gui/viewport.h"
#include "editor/gui/widget_log.h"

namespace sinew::editor::gui {

struct PanelState {
  std::array<char, 512> load_path{};
  std::array<char, 512> pack_path{};
  std::array<char, 512> limits_path{};
  int clip_a = 0;
  int clip_b = -1;
  float blend = 0.0f;
  int bone = 0;
  BakeSettings bake;
  int bake_clip = 0;
  anim::JointLimits limits;
  int joint = 0;

  // Clip, joint and limit state for a newly loaded model; the paths keep
  // what they hold (an empty load path takes the model's source).
  void reset_for(const character::Model& model, std::span<const anim::JointLimit> stored_limits);
  std::string load_path_text() const { return load_path.data(); }
  std::string pack_path_text() const { return pack_path.data(); }
  std::string limits_path_text() const { return limits_path.data(); }
};

// Copies `text` into a text field's buffer, cut to fit.
void copy_text(std::array<char, 512>& dst, const std::string& text);

struct PanelContext {
  const character::Model* model = nullptr;  // null: nothing loaded
  rt::FuzzyCharacterView fuzzy;
  PosePlayer* player = nullptr;
  Viewport* viewport = nullptr;
  const EditorStats* stats = nullptr;
  bool* playing = nullptr;
  bool bake_running = false;
  double bake_progress = 0.0;
  std::string bake_phase;
  bool can_save_pack = false;
  std::string message;
  WidgetLog* widgets = nullptr;  // when set, every widget drawn is appended
};

struct PanelActions {
  bool load = false;
  bool bake = false;
  bool cancel_bake = false;
  bool save_pack = false;
  bool save_limits = false;
  int action_clip = -1;  // a clip to trigger as a one-shot
};

PanelActions draw_editor_panels(PanelState& state, const PanelContext& ctx, float x, float height);

}  // namespace sinew::editor::gui
