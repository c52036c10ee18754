#include "runtime/display/pixel_display.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstring>
#include <string>

namespace sinew {

PixelDisplay::PixelDisplay() {
  glGenTextures(1, &texture_);
  glGenBuffers(1, &pbo_);
}

PixelDisplay::~PixelDisplay() {
  glDeleteBuffers(1, &pbo_);
  glDeleteTextures(1, &texture_);
}

Status PixelDisplay::present(int width, int height, std::span<const std::uint8_t> rgba,
                             int viewport_width, int viewport_height) {
  const std::size_t bytes = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4;
  if (width <= 0 || height <= 0 || rgba.size() != bytes) {
    return invalid_argument("frame", std::to_string(width) + "x" + std::to_string(height),
                            "RGBA8 frame size does not match its pixel count");
  }
  glBindTexture(GL_TEXTURE_2D, texture_);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo_);
  // Orphan the previous storage, then fill the new one.
  glBufferData(GL_PIXEL_UNPACK_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_DRAW);
  void* dst = glMapBuffer(GL_PIXEL_UNPACK_BUFFER, GL_WRITE_ONLY);
  if (dst == nullptr) {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    return make_error(ErrorCode::kIoError, "", "pixel buffer", "", "glMapBuffer failed");
  }
  std::memcpy(dst, rgba.data(), bytes);
  glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (width != tex_width_ || height != tex_height_) {
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    tex_width_ = width;
    tex_height_ = height;
  }
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);

  glViewport(0, 0, viewport_width, viewport_height);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_TEXTURE_2D);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  // Row 0 of the frame is the top of the image; texture row 0 is at v = 0.
  glBegin(GL_QUADS);
  glTexCoord2f(0, 1); glVertex2f(-1, -1);
  glTexCoord2f(1, 1); glVertex2f(1, -1);
  glTexCoord2f(1, 0); glVertex2f(1, 1);
  glTexCoord2f(0, 0); glVertex2f(-1, 1);
  glEnd();
  glDisable(GL_TEXTURE_2D);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    return make_error(ErrorCode::kIoError, "", "gl", std::to_string(err), "OpenGL error while presenting");
  }
  return {};
}

}  // namespace sinew
