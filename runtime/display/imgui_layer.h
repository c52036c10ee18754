// ImGuiLayer: Dear ImGui on a Window (GLFW input, OpenGL 2 drawing), for the
// demo's HUD and the editor's panels. One per window; the window's GL
// context must be current. Part of sinew_display, so nothing headless links
// ImGui.
#pragma once

#include <memory>

#include "runtime/core/expected.h"
#include "runtime/display/window.h"

namespace sinew {

class ImGuiLayer {
 public:
  // Errors: kInternal when a backend fails to initialise.
  static Expected<std::unique_ptr<ImGuiLayer>> create(Window& window);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  // Between begin_frame() and end_frame() the caller issues ImGui:: calls;
  // end_frame() draws them over whatever the frame already holds.
  void begin_frame();
  void end_frame();

  // True while ImGui uses the mouse or keyboard (over a panel, typing), so
  // the game ignores that input.
  bool wants_mouse() const;
  bool wants_keyboard() const;

 private:
  ImGuiLayer() = default;
};

}  // namespace sinew
