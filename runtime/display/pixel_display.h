// PixelDisplay: shows a CPU-rendered RGBA8 frame in the current GL context.
//
// The frame is streamed through a pixel buffer object (orphaned every frame,
// so the driver never stalls on the previous upload) into a texture drawn
// as a window-filling quad (paper section 4.1). Requires a current context
// (Window::create makes one current).
#pragma once

#include <cstdint>
#include <span>

#include "runtime/core/status.h"

namespace sinew {

class PixelDisplay {
 public:
  PixelDisplay();
  ~PixelDisplay();
  PixelDisplay(const PixelDisplay&) = delete;
  PixelDisplay& operator=(const PixelDisplay&) = delete;

  // Uploads a width x height RGBA8 frame (row 0 at the top) and draws it to
  // fill a viewport of viewport_width x viewport_height.
  Status present(int width, int height, std::span<const std::uint8_t> rgba, int viewport_width,
                 int viewport_height);

 private:
  unsigned texture_ = 0;
  unsigned pbo_ = 0;
  int tex_width_ = 0;
  int tex_height_ = 0;
};

}  // namespace sinew
