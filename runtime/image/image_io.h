// Image files through OpenImageIO: PNG for color, OpenEXR for float and
// uint32 AOVs (depth, normals, triangle and instance ids). Every write is
// atomic (runtime/io/atomic_file.h): a reader never sees half an image.
//
// Pixels are tightly packed, row-major, row 0 at the top, channels
// interleaved. The format follows the file extension of the path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/core/expected.h"

namespace sinew {

enum class PixelType : std::uint8_t { kU8, kF32, kU32 };

std::size_t pixel_type_size(PixelType type);

struct ImageDesc {
  int width = 0;
  int height = 0;
  int channels = 0;
  PixelType type = PixelType::kU8;

  std::size_t byte_size() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
           static_cast<std::size_t>(channels) * pixel_type_size(type);
  }
};

// An image read back from disk, in the file's own pixel type.
struct Image {
  ImageDesc desc;
  std::vector<std::byte> pixels;

  template <typename T>
  std::span<const T> as() const {
    return {reinterpret_cast<const T*>(pixels.data()), pixels.size() / sizeof(T)};
  }
};

// Writes `pixels` (desc.byte_size() bytes) to `path`. PNG accepts kU8 with 1-4
// channels; EXR accepts kF32 and kU32. Errors: kInvalidArgument for a
// mismatched size or a type the format cannot hold, kIoError with
// OpenImageIO's reason.
Status write_image(const std::string& path, const ImageDesc& desc,
                   std::span<const std::byte> pixels);

// Typed conveniences.
Status write_png(const std::string& path, int width, int height, int channels,
                 std::span<const std::uint8_t> pixels);
Status write_exr(const std::string& path, int width, int height, int channels,
                 std::span<const float> pixels);
Status write_exr(const std::string& path, int width, int height, int channels,
                 std::span<const std::uint32_t> pixels);

// Reads an image in its stored pixel type (8-bit PNG → kU8, float EXR →
// kF32, uint EXR → kU32; other types are converted to kF32).
Expected<Image> read_image(const std::string& path);

}  // namespace sinew
