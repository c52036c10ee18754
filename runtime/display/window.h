// Window: a GLFW window with an OpenGL 2.1 context, for the demo and the
// editor. Part of the sinew_display target, so headless builds and tools
// never link GLFW or GL.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/expected.h"

struct GLFWwindow;

namespace sinew {

struct WindowOptions {
  int width = 1024;
  int height = 1024;
  std::string title = "Sinew";
  bool vsync = false;  // the demo measures frame time, so no frame cap by default
  bool visible = true;
};

class Window {
 public:
  // Errors: kIoError when there is no display or no GL context (the caller
  // falls back to headless mode and says so).
  static Expected<std::unique_ptr<Window>> create(const WindowOptions& options);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  bool should_close() const;
  void request_close();
  void poll_events();
  void swap_buffers();
  void framebuffer_size(int* width, int* height) const;
  bool key_down(int glfw_key) const;
  bool mouse_button_down(int glfw_button) const;
  // The window's top-left corner in screen coordinates.
  void position(int* x, int* y) const;
  // Cursor position in window coordinates (pixels from the top-left).
  void cursor_position(double* x, double* y) const;
  // Reads the back buffer (what the next swap_buffers() shows) as RGBA8,
  // row 0 at the top: a screenshot of exactly what was drawn.
  std::vector<std::uint8_t> read_back_buffer(int* width, int* height) const;

  GLFWwindow* handle() const { return window_; }

  // True when a display server can be reached (DISPLAY or WAYLAND_DISPLAY set
  // and GLFW initialises); cheap enough to call before deciding on headless.
  static bool display_available();

 private:
  Window() = default;
  GLFWwindow* window_ = nullptr;
};

}  // namespace sinew
