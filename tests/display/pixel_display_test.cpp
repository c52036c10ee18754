// The display path for real: a GLFW window (under Xvfb in ctest), a frame
// uploaded through the pixel buffer object and drawn as a quad, then read
// back from the framebuffer. What is shown must be what was rendered,
// the right way up.
#include <gtest/gtest.h>

#include <GL/gl.h>

#include <cstdint>
#include <vector>

#include "runtime/display/pixel_display.h"
#include "runtime/display/window.h"

namespace sinew {
namespace {

std::vector<std::uint8_t> pattern(int w, int h, int frame) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w * h * 4));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>((y * w + x) * 4);
      rgba[i + 0] = static_cast<std::uint8_t>(x * 4);
      rgba[i + 1] = static_cast<std::uint8_t>(y * 4);
      rgba[i + 2] = static_cast<std::uint8_t>(frame * 50);
      rgba[i + 3] = 255;
    }
  }
  return rgba;
}

TEST(PixelDisplay, ShowsTheFrameAsRendered) {
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  WindowOptions options;
  options.width = 64;
  options.height = 64;
  options.title = "sinew display test";
  auto window = Window::create(options);
  ASSERT_TRUE(window.ok()) << window.status().message();
  PixelDisplay display;
  int vw = 0, vh = 0;
  (*window)->framebuffer_size(&vw, &vh);
  ASSERT_EQ(vw, 64);
  ASSERT_EQ(vh, 64);
  // Several frames: the PBO is orphaned and refilled each time.
  for (int frame = 0; frame < 3; ++frame) {
    const auto rgba = pattern(64, 64, frame);
    ASSERT_TRUE(display.present(64, 64, rgba, vw, vh).ok());
    glFinish();
    std::vector<std::uint8_t> shown(64 * 64 * 4);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, 64, 64, GL_RGBA, GL_UNSIGNED_BYTE, shown.data());
    // GL rows start at the bottom; frame rows start at the top.
    int mismatches = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        for (int c = 0; c < 3; ++c) {
          const int want = rgba[static_cast<std::size_t>((y * 64 + x) * 4 + c)];
          const int got = shown[static_cast<std::size_t>(((63 - y) * 64 + x) * 4 + c)];
          if (std::abs(want - got) > 1) ++mismatches;
        }
      }
    }
    EXPECT_EQ(mismatches, 0) << "frame " << frame;
    (*window)->swap_buffers();
  }
}

TEST(PixelDisplay, RejectsAMismatchedFrame) {
  ASSERT_TRUE(Window::display_available());
  auto window = Window::create({.width = 32, .height = 32, .title = "t", .vsync = false, .visible = true});
  ASSERT_TRUE(window.ok()) << window.status().message();
  PixelDisplay display;
  std::vector<std::uint8_t> short_frame(10);
  EXPECT_EQ(display.present(32, 32, short_frame, 32, 32).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace sinew
