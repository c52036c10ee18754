// sinew-image-diff A B [--max-channel-diff N] [--max-differing-pixels N]:
// compares the RGB channels of two 8-bit images of any format OpenImageIO
// reads (PNG, PPM). Prints the counts; exit 0 when within the limits, 1
// otherwise, 2 on usage or read errors. Used by the package test to compare
// the example host's output with sinew-editor render.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "runtime/image/image_io.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: sinew-image-diff A B [--max-channel-diff N] [--max-differing-pixels N]\n");
    return 2;
  }
  int max_channel_diff = 0;
  long max_differing = 0;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--max-channel-diff") {
      max_channel_diff = std::atoi(argv[i + 1]);
    } else if (flag == "--max-differing-pixels") {
      max_differing = std::atol(argv[i + 1]);
    } else {
      std::fprintf(stderr, "sinew-image-diff: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  const auto a = sinew::read_image(argv[1]);
  const auto b = sinew::read_image(argv[2]);
  for (const auto* image : {&a, &b}) {
    if (!image->ok()) {
      std::fprintf(stderr, "sinew-image-diff: %s\n", image->status().message().c_str());
      return 2;
    }
    if ((*image)->desc.type != sinew::PixelType::kU8 || (*image)->desc.channels < 3) {
      std::fprintf(stderr, "sinew-image-diff: expected 8-bit RGB or RGBA images\n");
      return 2;
    }
  }
  if (a->desc.width != b->desc.width || a->desc.height != b->desc.height) {
    std::fprintf(stderr, "sinew-image-diff: sizes differ: %dx%d and %dx%d\n", a->desc.width, a->desc.height,
                 b->desc.width, b->desc.height);
    return 1;
  }
  const auto pa = a->as<std::uint8_t>();
  const auto pb = b->as<std::uint8_t>();
  const std::size_t ca = static_cast<std::size_t>(a->desc.channels);
  const std::size_t cb = static_cast<std::size_t>(b->desc.channels);
  const std::size_t pixels = static_cast<std::size_t>(a->desc.width) * static_cast<std::size_t>(a->desc.height);
  long differing = 0;
  int worst = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    int pixel_worst = 0;
    for (std::size_t c = 0; c < 3; ++c) pixel_worst = std::max(pixel_worst, std::abs(int(pa[i * ca + c]) - int(pb[i * cb + c])));
    worst = std::max(worst, pixel_worst);
    differing += pixel_worst > max_channel_diff;
  }
  std::printf("sinew-image-diff: %zu pixels, %ld differ by more than %d, largest channel difference %d\n", pixels,
              differing, max_channel_diff, worst);
  return differing <= max_differing ? 0 : 1;
}
