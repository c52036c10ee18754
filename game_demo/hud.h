// The demo's heads-up display (Dear ImGui): frame rate, per-phase times,
// ray throughput, characters and escapes, the pose space the model was
// baked over, and the controls a player may change while it runs.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "game_demo/character_cost.h"
#include "game_demo/demo_session.h"

namespace sinew::demo {

// What the HUD shows about the last frame.
struct HudFrame {
  double fps = 0.0;  // smoothed over recent frames, display included
  std::vector<std::pair<std::string, double>> phases_ms;  // the last frame's
  std::uint64_t rays = 0;        // primary, shadow and ambient occlusion rays of the last frame
  double trace_ms = 0.0;         // their trace time
  // The soft-lighting costs apart: the last frame's shadow rays (hard or
  // soft) and ambient occlusion rays, each with its trace time.
  std::uint64_t shadow_rays = 0;
  double shadow_ms = 0.0;
  std::uint64_t ao_rays = 0;
  double ao_ms = 0.0;
  int characters = 0;
  int player = 0;
  CharacterCost per_character;  // the last frame's update and trace, per character
  std::size_t escaped_triangles = 0;  // in the last frame
  double fallback_ms = 0.0;           // building their fallback trees, the last frame
  int width = 0;
  int height = 0;
};

// What the HUD lets the player change; applied before the next frame.
struct HudControls {
  int threads = 1;
  int max_threads = 1;
  bool shadows = true;
  bool textures = true;     // textured materials show their textures
  bool watertight = false;  // the watertight triangle test instead of the fast one
  // Soft shadows and ambient occlusion, each a toggle over its own values,
  // which stay while it is off (so turning it on again restores them).
  bool soft_shadows = false;
  bool ambient_occlusion = false;
  SoftLighting soft = soft_preset();

  // The toggles and values from the session's lighting; values of what is
  // off start at the --soft preset's.
  void take(const SoftLighting& lighting);
  // What the session renders with: the values of what is on.
  SoftLighting soft_lighting() const;
};

// Draws the HUD window (call between ImGuiLayer::begin_frame and
// end_frame). Returns true when the player changed a control.
bool draw_hud(const HudFrame& frame, const BakeInfo& bake, HudControls& controls);

// Frame rate smoothed exponentially so the HUD's number is readable.
class FrameRateMeter {
 public:
  void add_frame(double milliseconds);
  double fps() const { return smoothed_ms_ > 0.0 ? 1000.0 / smoothed_ms_ : 0.0; }

 private:
  double smoothed_ms_ = 0.0;
};

}  // namespace sinew::demo
