#include "runtime/display/window.h"

#include <GLFW/glfw3.h>
#include <GL/gl.h>

#include <algorithm>
#include <cstdlib>

namespace sinew {
namespace {

std::string g_last_glfw_error;

void on_glfw_error(int code, const char* description) {
  g_last_glfw_error = "GLFW error " + std::to_string(code) + ": " + (description ? description : "");
}

// GLFW is process-global; initialise once and terminate at exit.
bool ensure_glfw() {
  static const bool ok = [] {
    glfwSetErrorCallback(on_glfw_error);
    if (glfwInit() != GLFW_TRUE) return false;
    std::atexit(glfwTerminate);
    return true;
  }();
  return ok;
}

}  // namespace

bool Window::display_available() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wayland == nullptr || *wayland == '\0')) return false;
  return ensure_glfw();
}

Expected<std::unique_ptr<Window>> Window::create(const WindowOptions& options) {
  if (!ensure_glfw()) {
    return make_error(ErrorCode::kIoError, "", "display", "", "cannot initialise GLFW: " + g_last_glfw_error);
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
  GLFWwindow* handle =
      glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (handle == nullptr) {
    return make_error(ErrorCode::kIoError, "", "window",
                      std::to_string(options.width) + "x" + std::to_string(options.height),
                      "cannot create window: " + g_last_glfw_error);
  }
  glfwMakeContextCurrent(handle);
  glfwSwapInterval(options.vsync ? 1 : 0);
  std::unique_ptr<Window> window(new Window());
  window->window_ = handle;
  return window;
}

Window::~Window() {
  if (window_ != nullptr) glfwDestroyWindow(window_);
}

bool Window::should_close() const { return glfwWindowShouldClose(window_) == GLFW_TRUE; }
void Window::request_close() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void Window::poll_events() { glfwPollEvents(); }
void Window::swap_buffers() { glfwSwapBuffers(window_); }
void Window::framebuffer_size(int* width, int* height) const {
  glfwGetFramebufferSize(window_, width, height);
}
bool Window::key_down(int glfw_key) const { return glfwGetKey(window_, glfw_key) == GLFW_PRESS; }
bool Window::mouse_button_down(int glfw_button) const {
  return glfwGetMouseButton(window_, glfw_button) == GLFW_PRESS;
}
void Window::position(int* x, int* y) const { glfwGetWindowPos(window_, x, y); }
void Window::cursor_position(double* x, double* y) const { glfwGetCursorPos(window_, x, y); }

std::vector<std::uint8_t> Window::read_back_buffer(int* width, int* height) const {
  framebuffer_size(width, height);
  const auto w = static_cast<std::size_t>(*width);
  const auto h = static_cast<std::size_t>(*height);
  std::vector<std::uint8_t> bottom_up(w * h * 4);
  glFinish();
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, *width, *height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  // GL rows start at the bottom; images here start at the top.
  std::vector<std::uint8_t> top_down(bottom_up.size());
  for (std::size_t y = 0; y < h; ++y) {
    std::copy_n(bottom_up.data() + (h - 1 - y) * w * 4, w * 4, top_down.data() + y * w * 4);
  }
  return top_down;
}

}  // namespace sinew
