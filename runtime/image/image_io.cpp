#include "runtime/image/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cctype>
#include <string_view>

#include "runtime/io/atomic_file.h"

namespace sinew {
namespace {

OIIO::TypeDesc oiio_type(PixelType type) {
  switch (type) {
    case PixelType::kU8: return OIIO::TypeDesc::UINT8;
    case PixelType::kF32: return OIIO::TypeDesc::FLOAT;
    case PixelType::kU32: return OIIO::TypeDesc::UINT32;
  }
  return OIIO::TypeDesc::UNKNOWN;
}

std::string extension_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

std::size_t pixel_type_size(PixelType type) {
  switch (type) {
    case PixelType::kU8: return 1;
    case PixelType::kF32: return 4;
    case PixelType::kU32: return 4;
  }
  return 0;
}

Status write_image(const std::string& path, const ImageDesc& desc,
                   std::span<const std::byte> pixels) {
  if (desc.width <= 0 || desc.height <= 0) {
    return invalid_argument("image size",
                            std::to_string(desc.width) + "x" + std::to_string(desc.height),
                            "width and height must be positive");
  }
  if (desc.channels < 1 || desc.channels > 4) {
    return invalid_argument("channels", std::to_string(desc.channels), "must be 1 to 4");
  }
  if (pixels.size() != desc.byte_size()) {
    return invalid_argument("pixels", std::to_string(pixels.size()) + " bytes",
                            "expected " + std::to_string(desc.byte_size()) + " bytes for " +
                                std::to_string(desc.width) + "x" + std::to_string(desc.height) +
                                "x" + std::to_string(desc.channels));
  }
  const std::string ext = extension_of(path);
  if (ext == "png" && desc.type != PixelType::kU8) {
    return invalid_argument("pixel type", path, "PNG holds 8-bit color; write float or id AOVs as .exr");
  }
  if (ext == "exr" && desc.type == PixelType::kU8) {
    return invalid_argument("pixel type", path, "write 8-bit color as .png");
  }

  // OpenImageIO writes the file itself, so write beside the destination
  // under a temporary name with the same extension, then rename.
  const std::string temp = temp_path_beside(path);
  auto out = OIIO::ImageOutput::create(temp);
  if (!out) {
    return make_error(ErrorCode::kIoError, path, "", "",
                      "no image writer for this extension: " + OIIO::geterror());
  }
  OIIO::ImageSpec spec(desc.width, desc.height, desc.channels, oiio_type(desc.type));
  if (ext == "exr") spec.attribute("compression", "zip");
  // Our RGBA is straight (unassociated) alpha; without this OpenImageIO would
  // divide color by alpha on write and lose precision.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->open(temp, spec)) {
    return make_error(ErrorCode::kIoError, path, "", "", "cannot open for writing: " + out->geterror());
  }
  const bool wrote = out->write_image(oiio_type(desc.type), pixels.data());
  const bool closed = out->close();
  if (!wrote || !closed) {
    const std::string why = out->geterror();
    ::unlink(temp.c_str());
    return make_error(ErrorCode::kIoError, path, "", "", "write failed: " + why);
  }
  return replace_file_atomic(temp, path);
}

Status write_png(const std::string& path, int width, int height, int channels,
                 std::span<const std::uint8_t> pixels) {
  return write_image(path, {width, height, channels, PixelType::kU8}, std::as_bytes(pixels));
}

Status write_exr(const std::string& path, int width, int height, int channels,
                 std::span<const float> pixels) {
  return write_image(path, {width, height, channels, PixelType::kF32}, std::as_bytes(pixels));
}

Status write_exr(const std::string& path, int width, int height, int channels,
                 std::span<const std::uint32_t> pixels) {
  return write_image(path, {width, height, channels, PixelType::kU32}, std::as_bytes(pixels));
}

Expected<Image> read_image(const std::string& path) {
  // Read alpha back as stored, not premultiplied (see write_image).
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) {
    return make_error(::access(path.c_str(), F_OK) == 0 ? ErrorCode::kIoError : ErrorCode::kNotFound,
                      path, "", "", "cannot open image: " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = in->spec();
  Image image;
  image.desc.width = spec.width;
  image.desc.height = spec.height;
  image.desc.channels = spec.nchannels;
  if (spec.format == OIIO::TypeDesc::UINT8) {
    image.desc.type = PixelType::kU8;
  } else if (spec.format == OIIO::TypeDesc::UINT32) {
    image.desc.type = PixelType::kU32;
  } else {
    image.desc.type = PixelType::kF32;
  }
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
      image.desc.byte_size() > (std::size_t{1} << 32)) {
    return make_error(ErrorCode::kLimitExceeded, path, "size",
                      std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                          std::to_string(spec.nchannels),
                      "image dimensions out of range");
  }
  image.pixels.resize(image.desc.byte_size());
  if (!in->read_image(0, 0, 0, spec.nchannels, oiio_type(image.desc.type), image.pixels.data())) {
    return make_error(ErrorCode::kIoError, path, "", "", "read failed: " + in->geterror());
  }
  in->close();
  return image;
}

}  // namespace sinew
