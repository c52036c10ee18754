// A host's own surfaces as the origins of Sinew's light rays: per pixel the
// world position and unit normal its rasteriser wrote (a G-buffer), which
// Renderer::render_visibility (render/renderer.h) shadows and occludes with
// Sinew's characters and static meshes. The host's surfaces are receivers
// only: they are not in Sinew's scene and block nothing. The caller owns
// every buffer; they are read, never written.
#pragma once

#include <cstddef>
#include <span>

#include "runtime/math/types.h"

namespace sinew::rt {

// HostSurfaces::normal_offset's "choose for me": kAutomaticOffsetScale times
// the diagonal of the scene's world box this frame.
inline constexpr float kAutomaticNormalOffset = -1.0f;
inline constexpr float kAutomaticOffsetScale = 1e-4f;

struct HostSurfaces {
  int width = 0;
  int height = 0;
  // Per pixel, row-major, y = 0 on top, width * height entries unless a row
  // pitch is given. A pixel has no surface (its masks are 1) where its
  // position is not finite or its normal is zero or not finite: the sky, or
  // what the host left empty. Normals are unit; one a little off unit (an
  // 8- or 16-bit encoding) is normalised.
  std::span<const Vec3> position;  // world space
  std::span<const Vec3> normal;    // world space, on the side the light rays leave from
  // How far every ray's origin is pushed off the host's surface along its
  // normal (world units), so that a host surface that coincides with one of
  // Sinew's (the host rasterises the characters too, or a floor Sinew also
  // holds) does not shadow itself through the rounding of the host's
  // reconstructed position. kAutomaticNormalOffset (or any negative value):
  // kAutomaticOffsetScale times the scene's size. A point light's shadow
  // rays are pushed a little further by the rounding of their own
  // arithmetic (render/surface.h shadow_ray_from_light).
  float normal_offset = kAutomaticNormalOffset;
  // Optional, per pixel in place of normal_offset: a bound on the rounding
  // of each coordinate of the position (render/surface.h
  // SurfacePoint::error); the origin moves by it times |nx| + |ny| + |nz|
  // along the normal, as it does from Sinew's own hits. A pixel whose bound
  // is negative or not finite has no surface.
  std::span<const float> position_error;

  // Bytes from one row to the next, per buffer; 0: rows packed. A pitch
  // holds at least a row and is a multiple of 4 bytes.
  struct RowPitches {
    std::size_t position = 0;
    std::size_t normal = 0;
    std::size_t position_error = 0;
  };
  RowPitches row_pitch;
};

}  // namespace sinew::rt
