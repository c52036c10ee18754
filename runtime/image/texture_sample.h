// Sampling a Texture (texture.h): the mip level a pixel's footprint asks
// for, and a bilinear lookup in one level. The renderer's surface stage
// calls these per textured lane; they are inline because a frame calls
// them once per textured pixel.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "runtime/image/texture.h"
#include "runtime/math/types.h"

namespace sinew {

// The level whose texels best match a pixel's footprint (Akenine-Möller et
// al., "Texture Level of Detail Strategies for Real-Time Ray Tracing",
// Ray Tracing Gems, 2019: the triangle's texel-to-world area ratio times
// the pixel cone's width at the hit). `uv_per_pixel2` is (uv area / world
// area of the triangle) * (the footprint's width in world units)^2: the
// pixel's area in uv units. Level 0 texels cover 1 / (width * height) of
// uv space each, so the level is log2 of the texels a pixel covers, halved
// (each level quarters the texel count), rounded to the nearest level. The
// logarithm is the float's exponent plus its mantissa's fraction, exact at
// powers of two and within 0.09 between: a level choice, not a value.
// Branch-free: neighbouring pixels often straddle a level boundary, and a
// mispredicted branch per lookup would cost more than the lookup.
inline std::uint32_t texture_level(const Texture& texture, float uv_per_pixel2) {
  float texels = uv_per_pixel2 * static_cast<float>(texture.levels[0].width) *
                 static_cast<float>(texture.levels[0].height);
  // Magnified (and a degenerate uv triangle, NaN included): level 0; a
  // degenerate world triangle (infinity): past the last level, clamped below.
  texels = texels > 1.0f ? texels : 1.0f;
  texels = texels < 1.0e38f ? texels : 1.0e38f;
  const auto bits = std::bit_cast<std::uint32_t>(texels);
  const float log2 = static_cast<float>(static_cast<int>(bits >> 23) - 127) +
                     static_cast<float>(bits & 0x7FFFFFu) * (1.0f / 8388608.0f);
  const auto level = static_cast<std::uint32_t>(0.5f * log2 + 0.5f);
  const auto last = static_cast<std::uint32_t>(texture.levels.size() - 1);
  return level < last ? level : last;
}

namespace texture_detail {

// `c` (in [0, 1) texture space after wrapping, times the side) split into
// the two texel columns (or rows) a bilinear lookup blends and the weight
// of the second.
struct Taps {
  std::uint32_t i0, i1;
  float weight;
};

inline float wrapped(float c, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kClamp: return std::clamp(c, 0.0f, 1.0f);
    case TextureWrap::kMirror: {
      const float f = c - 2.0f * std::floor(0.5f * c);  // [0, 2)
      return f > 1.0f ? 2.0f - f : f;
    }
    case TextureWrap::kRepeat: break;
  }
  return c - std::floor(c);
}

inline Taps taps(float c, std::uint32_t side, TextureWrap wrap) {
  // Texel centres sit at (i + 0.5) / side.
  const float x = wrapped(c, wrap) * static_cast<float>(side) - 0.5f;
  const float x0 = std::floor(x);
  const float weight = x - x0;
  // x0 is in [-1, side - 1] (wrapped() is in [0, 1]; rounding can reach 1).
  const int first = static_cast<int>(x0);
  const int last = static_cast<int>(side) - 1;
  int i0 = first, i1 = first + 1;
  if (wrap == TextureWrap::kRepeat) {
    if (i0 < 0) i0 = last;
    if (i1 > last) i1 = 0;
  } else {  // clamp, and mirror's reflection at an edge repeats the edge texel
    i0 = std::clamp(i0, 0, last);
    i1 = std::clamp(i1, 0, last);
  }
  return {static_cast<std::uint32_t>(i0), static_cast<std::uint32_t>(i1), weight};
}

}  // namespace texture_detail

// The linear RGB of `texture`'s level `level` at `uv`, bilinearly
// filtered, the level's wrap modes applied. `uv` must be finite.
inline Vec3 sample_bilinear(const Texture& texture, std::uint32_t level, Vec2 uv) {
  const TextureLevel& l = texture.levels[level];
  const texture_detail::Taps tx = texture_detail::taps(uv.x, l.width, texture.wrap_u);
  const texture_detail::Taps ty = texture_detail::taps(uv.y, l.height, texture.wrap_v);
  const Texel16* row0 = &l.texels[static_cast<std::size_t>(ty.i0) * l.width];
  const Texel16* row1 = &l.texels[static_cast<std::size_t>(ty.i1) * l.width];
  const float w00 = (1.0f - tx.weight) * (1.0f - ty.weight), w10 = tx.weight * (1.0f - ty.weight);
  const float w01 = (1.0f - tx.weight) * ty.weight, w11 = tx.weight * ty.weight;
  Vec3 out;
  for (int c = 0; c < 3; ++c) {
    out[c] = (w00 * row0[tx.i0][c] + w10 * row0[tx.i1][c] + w01 * row1[tx.i0][c] + w11 * row1[tx.i1][c]) *
             (1.0f / 65535.0f);
  }
  return out;
}

}  // namespace sinew
