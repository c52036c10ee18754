#include "runtime/image/texture_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cstring>
#include <filesystem>
#include <vector>

namespace sinew {
namespace {

// OpenImageIO's format name for glTF's mime type, or for the bytes'
// signature; "" when neither says.
std::string_view format_of(std::span<const std::byte> bytes, std::string_view mime_type) {
  if (mime_type == "image/png") return "png";
  if (mime_type == "image/jpeg") return "jpeg";
  const auto starts = [&](std::string_view magic) {
    return bytes.size() >= magic.size() && std::memcmp(bytes.data(), magic.data(), magic.size()) == 0;
  };
  if (starts("\x89PNG")) return "png";
  if (starts("\xFF\xD8\xFF")) return "jpeg";
  if (starts("DDS ")) return "dds";
  if (starts("BM")) return "bmp";
  if (starts("\x76\x2F\x31\x01")) return "openexr";
  if (starts("II*") || starts("MM\0*")) return "tiff";
  return "targa";  // TGA has no signature
}

std::string oiio_reason(const OIIO::ImageInput* in) {
  std::string why = in != nullptr ? in->geterror() : OIIO::geterror();
  while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
  return why.empty() ? "OpenImageIO could not read it" : why;
}

// Reads the open image's first subimage as linear RGBA floats.
Expected<Texture> decode_open(OIIO::ImageInput& in, const std::string& name, TextureWrap wrap_u,
                              TextureWrap wrap_v) {
  const OIIO::ImageSpec& spec = in.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1) {
    return make_error(ErrorCode::kInvalidData, name, "size",
                      std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                          std::to_string(spec.nchannels),
                      "not a 2D image");
  }
  const auto w = static_cast<std::uint32_t>(spec.width), h = static_cast<std::uint32_t>(spec.height);
  if (w > kMaxImportedTextureSide || h > kMaxImportedTextureSide) {
    return make_error(ErrorCode::kLimitExceeded, name, "size", std::to_string(w) + "x" + std::to_string(h),
                      "textures are at most " + std::to_string(kMaxImportedTextureSide) + " texels a side");
  }
  const int channels = std::min(spec.nchannels, 4);
  const std::size_t count = static_cast<std::size_t>(w) * h;
  std::vector<float> read(count * static_cast<std::size_t>(channels));
  if (!in.read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, read.data())) {
    return make_error(ErrorCode::kInvalidData, name, "pixels", "", oiio_reason(&in));
  }
  const bool encoded = !spec.format.is_floating_point();
  const auto colour = [&](float x) { return encoded ? srgb_to_linear(x) : x; };
  std::vector<float> rgba(count * 4);
  for (std::size_t i = 0; i < count; ++i) {
    const float* p = &read[i * static_cast<std::size_t>(channels)];
    float* q = &rgba[i * 4];
    if (channels <= 2) {
      q[0] = q[1] = q[2] = colour(p[0]);
      q[3] = channels == 2 ? p[1] : 1.0f;
    } else {
      for (int c = 0; c < 3; ++c) q[c] = colour(p[c]);
      q[3] = channels == 4 ? p[3] : 1.0f;
    }
  }
  return make_texture(name, w, h, rgba, wrap_u, wrap_v);
}

}  // namespace

Expected<Texture> decode_texture(std::span<const std::byte> encoded, std::string_view mime_type, std::string name,
                                 TextureWrap wrap_u, TextureWrap wrap_v) {
  const std::string format(format_of(encoded, mime_type));
  OIIO::Filesystem::IOMemReader memory(encoded.data(), encoded.size());
  // The name only picks the decoder; the bytes come from `memory`.
  auto in = OIIO::ImageInput::open("memory." + format, nullptr, &memory);
  if (!in) {
    return make_error(ErrorCode::kInvalidData, name, "bytes", std::to_string(encoded.size()) + " bytes",
                      "not a readable " + format + " image: " + oiio_reason(nullptr));
  }
  Expected<Texture> texture = decode_open(*in, name, wrap_u, wrap_v);
  in->close();
  return texture;
}

Expected<Texture> read_texture(const std::string& path, TextureWrap wrap_u, TextureWrap wrap_v) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return make_error(ErrorCode::kNotFound, path, "", "", "no such file");
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) return make_error(ErrorCode::kInvalidData, path, "", "", oiio_reason(nullptr));
  Expected<Texture> texture = decode_open(*in, path, wrap_u, wrap_v);
  in->close();
  return texture;
}

}  // namespace sinew
