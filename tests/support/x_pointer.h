// XPointer: the X server's real pointer, moved and clicked through the XTest
// extension, the way xdotool does it. The server turns these into the same
// MotionNotify/ButtonPress events a mouse makes, so the window under test
// (GLFW, then Dear ImGui) reads them through its ordinary input path.
// Needs a display (ctest runs these tests under xvfb-run).
#pragma once

#include <X11/Xlib.h>
#include <X11/extensions/XTest.h>

namespace sinew::testing_support {

class XPointer {
 public:
  XPointer() : display_(XOpenDisplay(nullptr)) {
    int event_base = 0, error_base = 0, major = 0, minor = 0;
    has_xtest_ = display_ != nullptr && XTestQueryExtension(display_, &event_base, &error_base, &major, &minor);
  }
  ~XPointer() {
    if (display_ != nullptr) XCloseDisplay(display_);
  }
  XPointer(const XPointer&) = delete;
  XPointer& operator=(const XPointer&) = delete;

  // False without a display or without the XTest extension.
  bool ok() const { return has_xtest_; }

  // Screen coordinates, pixels from the top-left of screen 0. Each call
  // returns once the server has processed the event.
  void move_to(int x, int y) {
    XTestFakeMotionEvent(display_, 0, x, y, CurrentTime);
    XSync(display_, False);
  }
  void left_button(bool down) {
    XTestFakeButtonEvent(display_, Button1, down ? True : False, CurrentTime);
    XSync(display_, False);
  }

 private:
  Display* display_ = nullptr;
  bool has_xtest_ = false;
};

}  // namespace sinew::testing_support
