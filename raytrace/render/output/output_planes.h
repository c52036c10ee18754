// Where the renderer writes each requested output (AOV): one plane per
// output, rows `pitch` bytes apart (packed, or the host's padded layout),
// null when not requested. Built from the host's FrameBuffers with their
// size and pitch checks (render/renderer.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "runtime/core/expected.h"
#include "runtime/math/types.h"

namespace sinew::rt {

template <class T>
struct OutputPlane {
  std::byte* base = nullptr;  // null: not requested
  std::size_t pitch = 0;
  std::size_t channels = 1;
  // The pixel at `base`: (0, 0) for a whole image, a tile's corner for
  // its staging plane (render/output/output_staging.h).
  int x0 = 0, y0 = 0;

  bool wanted() const { return base != nullptr; }
  T* at(int x, int y) const {
    return reinterpret_cast<T*>(base + static_cast<std::size_t>(y - y0) * pitch) +
           static_cast<std::size_t>(x - x0) * channels;
  }
};

// The plane over `span` for a width x height image with `channels`
// elements per pixel; `pitch` 0 means packed rows. Errors name `name`.
template <class T>
Expected<OutputPlane<T>> output_plane(std::span<T> span, std::size_t pitch, std::size_t channels, int width,
                                      int height, std::string_view name) {
  OutputPlane<T> plane;
  if (span.empty()) return plane;
  const std::size_t w = static_cast<std::size_t>(width);
  const std::size_t h = static_cast<std::size_t>(height);
  const std::size_t row_bytes = w * channels * sizeof(T);
  if (pitch == 0) {
    if (span.size() != w * h * channels) {
      return invalid_argument(name, std::to_string(span.size()),
                              "expected " + std::to_string(w * h * channels) + " entries");
    }
    pitch = row_bytes;
  } else {
    const std::string pitch_field = "row_pitch." + std::string(name.substr(name.find('.') + 1));
    if (pitch < row_bytes) {
      return invalid_argument(pitch_field, std::to_string(pitch),
                              "below one row of " + std::to_string(row_bytes) + " bytes");
    }
    if (pitch % alignof(T) != 0) {
      return invalid_argument(pitch_field, std::to_string(pitch),
                              "not a multiple of the element alignment " + std::to_string(alignof(T)));
    }
    const std::size_t needed = (h - 1) * pitch + row_bytes;
    if (span.size_bytes() < needed) {
      return invalid_argument(name, std::to_string(span.size_bytes()) + " bytes",
                              "the rows need " + std::to_string(needed) + " bytes at this pitch");
    }
  }
  plane.base = reinterpret_cast<std::byte*>(span.data());
  plane.pitch = pitch;
  plane.channels = channels;
  return plane;
}

// Every output of one render.
struct OutputPlanes {
  OutputPlane<std::uint8_t> rgba8;
  OutputPlane<float> rgba32f;
  OutputPlane<float> depth;
  OutputPlane<Vec3> normal;
  OutputPlane<std::uint32_t> triangle;
  OutputPlane<std::uint32_t> instance;
  OutputPlane<Vec2> uv;
  OutputPlane<Vec2> barycentric;
  OutputPlane<std::uint32_t> material;
  OutputPlane<float> shadow;  // one channel per light
  OutputPlane<float> ambient_occlusion;

  bool want_color() const { return rgba8.wanted() || rgba32f.wanted(); }
  // The hit's uv and material: read from the mesh with the surfaces.
  bool want_hit_attributes() const { return uv.wanted() || material.wanted(); }
  // The shadow and ambient occlusion rays: for the colour or their masks.
  bool want_light_rays() const { return want_color() || shadow.wanted() || ambient_occlusion.wanted(); }
  bool want_surface() const { return want_light_rays() || normal.wanted() || want_hit_attributes(); }
  // Any output besides colour RGBA8 (which has a path of its own).
  bool want_other_than_rgba8() const {
    return rgba32f.wanted() || depth.wanted() || normal.wanted() || triangle.wanted() || instance.wanted() ||
           uv.wanted() || barycentric.wanted() || material.wanted() || shadow.wanted() ||
           ambient_occlusion.wanted();
  }
};

// fn(a.p, b.p) for every plane p, the planes of `a` and `b` paired by kind
// (either may be const).
template <class A, class B, class Fn>
void for_each_plane_pair(A& a, B& b, Fn&& fn) {
  fn(a.rgba8, b.rgba8);
  fn(a.rgba32f, b.rgba32f);
  fn(a.depth, b.depth);
  fn(a.normal, b.normal);
  fn(a.triangle, b.triangle);
  fn(a.instance, b.instance);
  fn(a.uv, b.uv);
  fn(a.barycentric, b.barycentric);
  fn(a.material, b.material);
  fn(a.shadow, b.shadow);
  fn(a.ambient_occlusion, b.ambient_occlusion);
}

}  // namespace sinew::rt
