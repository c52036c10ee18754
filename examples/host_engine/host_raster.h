// The host engine's own rendering: a tiny z-buffered software rasteriser
// standing in for whatever a real engine draws (its level, its sky), in two
// steps as a deferred renderer draws: a G-buffer (depth, world position,
// normal), then the shading, which takes Sinew's shadow mask of those very
// surfaces (the pass's G-buffer mode), so the characters' soft shadows fall
// on the host's ground. Then the depth composite that merges Sinew's own
// image of the characters into that frame.
//
// The contract that makes the composite work: the host's camera is the same
// pinhole camera as Sinew's (sinew/pass.h Camera, y = 0 the top row), and the
// host's depth is the same quantity as Sinew's depth output: the distance
// from the eye along the unit view ray through the pixel centre, +inf where
// nothing was drawn. (Not the NDC z a GPU z-buffer holds: an engine that
// composites against a GPU depth buffer converts one into the other.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <sinew/sinew.h>

namespace host {

struct Vec3 {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
};

// An image the host owns, with padded rows: Sinew writes into it through
// OutputBuffer{data, row_pitch}, so the padding exercises the pitch API the
// way a GPU upload buffer (rows aligned to 256 bytes) would.
class Image {
 public:
  static constexpr std::size_t kRowAlignment = 256;

  Image(int width, int height, std::size_t bytes_per_pixel);

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t row_pitch() const { return row_pitch_; }
  std::byte* data() { return reinterpret_cast<std::byte*>(storage_.data()); }
  const std::byte* data() const { return reinterpret_cast<const std::byte*>(storage_.data()); }
  sinew::api::OutputBuffer as_output() { return {data(), row_pitch_}; }

  template <class T>
  T* row(int y) {
    return reinterpret_cast<T*>(data() + static_cast<std::size_t>(y) * row_pitch_);
  }
  template <class T>
  const T* row(int y) const {
    return reinterpret_cast<const T*>(data() + static_cast<std::size_t>(y) * row_pitch_);
  }

 private:
  int width_;
  int height_;
  std::size_t row_pitch_;
  // 32-bit words keep every row (pitch a multiple of 256) float-aligned.
  std::vector<std::uint32_t> storage_;
};

inline constexpr float kFarAway = std::numeric_limits<float>::infinity();

// Sinew's camera convention, restated in the host's terms.
struct PinholeCamera {
  Vec3 eye;
  Vec3 forward;  // normalize(target - eye)
  Vec3 right;    // normalize(cross(forward, up))
  Vec3 up;       // cross(right, forward)
  float tan_half_fovy = 0.0f;
  float aspect = 1.0f;
  int width = 1;
  int height = 1;

  static PinholeCamera from(const sinew::api::Camera& camera, int width, int height);
  // The unit ray through the centre of pixel (x, y), y = 0 the top row.
  Vec3 ray_direction(int x, int y) const;
};

// A ground quad: the plane where `up_axis` (1: Y, 2: Z) equals `height`,
// spanning [center - half_size, center + half_size] on the other two axes.
struct Ground {
  int up_axis = 1;
  float height = 0.0f;
  Vec3 center;
  float half_size = 10.0f;
  float checker_size = 0.5f;  // the checkerboard's squares: in scale with the character
};

struct HostLighting {
  Vec3 light_position;
  Vec3 ambient{0.18f, 0.18f, 0.18f};  // Sinew's default, so both passes read as one scene
};

// What the host's rasteriser leaves per pixel for its shading (and for
// Sinew's G-buffer mode, which reads position and normal as they are: 3
// floats a pixel, rows row_pitch() bytes apart).
struct GBuffer {
  GBuffer(int width, int height)
      : depth(width, height, sizeof(float)), position(width, height, sizeof(Vec3)), normal(width, height, sizeof(Vec3)) {}
  Image depth;     // float: the ray distance; kFarAway where nothing was drawn
  Image position;  // Vec3: world position; NaN where nothing was drawn (no surface for Sinew)
  Image normal;    // Vec3: unit world normal; 0 where nothing was drawn
};

// The host pass, first half: clears the G-buffer (depth +inf, no surface),
// then draws the ground as two z-buffered triangles into it.
void draw_host_gbuffer(const PinholeCamera& camera, const Ground& ground, GBuffer& gbuffer);

// The host pass, second half: a sky gradient where nothing was drawn; the
// ground's checkerboard lit by the ambient light and the point light, whose
// direct light is scaled by `shadow` (float per pixel: the fraction of the
// light that reaches the surface, Sinew's shadow mask). Colour: RGBA8 sRGB,
// like Sinew's kColorRgba8.
void shade_host_pass(const PinholeCamera& camera, const Ground& ground, const HostLighting& lighting,
                     const GBuffer& gbuffer, const Image& shadow, Image& color);

// Per pixel: Sinew's colour where Sinew's depth is nearer than the host's,
// else the host's. Writes into the host's buffers (colour and depth), so a
// later host pass (transparent effects, UI) sees the merged frame.
void composite_by_depth(const Image& sinew_color, const Image& sinew_depth, Image& host_color,
                        Image& host_depth);

// After the composite: blends the pixels that show instance `selected`
// (Sinew's instance-id output) halfway toward orange. Only where the
// composite kept Sinew's pixel: where the host's pass hides part of the
// character, the highlight must not show through.
void highlight_instance(const Image& instance_ids, const Image& sinew_depth, std::uint32_t selected,
                        Image& host_color, const Image& host_depth);

}  // namespace host
