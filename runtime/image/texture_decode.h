// Textures from encoded images, through OpenImageIO: PNG, JPEG, TGA, DDS,
// BMP, OpenEXR and TIFF, from a file or from bytes in memory (a glTF
// buffer view or data URI). 8- and 16-bit images are taken as sRGB (what
// glTF requires of a base colour texture, and what Cal3D's TGAs hold) and
// converted to linear here, once; float images are already linear. One
// channel is grey, two grey and alpha, three RGB (alpha 1).
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "runtime/core/expected.h"
#include "runtime/image/texture.h"

namespace sinew {

// The largest side an imported image may have: a bound on the memory one
// image takes while it is decoded.
inline constexpr std::uint32_t kMaxImportedTextureSide = 8192;

// `mime_type` (glTF's images[i].mimeType, "image/png") picks the decoder
// when given; otherwise the bytes' signature does (PNG, JPEG, DDS, BMP,
// EXR, TIFF; anything else is tried as TGA, which has none). Errors
// (naming `name`): kInvalidData when nothing can decode the bytes,
// kLimitExceeded past kMaxImportedTextureSide.
Expected<Texture> decode_texture(std::span<const std::byte> encoded, std::string_view mime_type, std::string name,
                                 TextureWrap wrap_u, TextureWrap wrap_v);

// The same from a file, its format from its contents or extension. Errors
// also kNotFound and kIoError.
Expected<Texture> read_texture(const std::string& path, TextureWrap wrap_u, TextureWrap wrap_v);

}  // namespace sinew
