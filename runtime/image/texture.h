// Texture: a material's colour map as the renderer samples it. Texels are
// linear RGBA in 16-bit unsigned normalised integers (sRGB files are
// converted once, when the texture is made, and 16 bits keep the darks
// that 8-bit linear would band). Level 0 is the image; each further level
// halves both sides (rounding down, never below 1) by averaging the 2x2
// (or 2x1, 1x2) texels it covers, down to 1x1. Row 0 is the image's top
// row; texture coordinate (0, 0) is its top-left corner and v grows
// downwards, as in glTF and Cal3D.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/core/expected.h"

namespace sinew {

// How coordinates outside [0, 1) reach the image (glTF's sampler modes).
enum class TextureWrap : std::uint8_t { kRepeat = 0, kClamp = 1, kMirror = 2 };

// The largest side a texture may have: a 16384-wide RGBA16 level is 2 GiB,
// so nothing larger is made or loaded.
inline constexpr std::uint32_t kMaxTextureSide = 16384;

using Texel16 = std::array<std::uint16_t, 4>;  // linear RGBA, 65535 = 1

struct TextureLevel {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<Texel16> texels;  // width * height, row-major
};

struct Texture {
  std::string name;  // the file (or glTF image) it came from, for messages
  TextureWrap wrap_u = TextureWrap::kRepeat;
  TextureWrap wrap_v = TextureWrap::kRepeat;
  std::vector<TextureLevel> levels;  // the full chain, level 0 first
};

// The linear value of an sRGB-encoded one in [0, 1] (IEC 61966-2-1).
float srgb_to_linear(float encoded);

// A texel of linear values in [0, 1] (clamped; NaN reads as 0).
Texel16 texel_from_linear(float r, float g, float b, float a);

// Level 0 from `linear` (width * height RGBA floats, row-major) and the
// full mip chain below it. Errors (kInvalidArgument naming `name`): a side
// of 0 or above kMaxTextureSide, or a pixel count that is not width *
// height * 4 floats.
Expected<Texture> make_texture(std::string name, std::uint32_t width, std::uint32_t height,
                               std::span<const float> linear, TextureWrap wrap_u, TextureWrap wrap_v);

// The next level's size: half, rounded down, at least 1.
inline std::uint32_t mip_side(std::uint32_t side) { return side > 1 ? side / 2 : 1; }

// Checks a texture made elsewhere (a pack's): sides within limits, each
// level's size the one mip_side gives and holding width * height texels,
// the chain ending at 1x1, the wrap modes known. kInvalidData naming
// `file` and `field` (e.g. "TEXR.textures[2].levels[3].width").
Status check_texture(const Texture& texture, std::string_view file, const std::string& field);

}  // namespace sinew
