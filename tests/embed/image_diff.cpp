// sinew-image-diff A B [--max-channel-diff N] [--max-differing-pixels N]:
// compares the RGB channels of two 8-bit images of any format OpenImageIO
// reads (PNG, PPM). Prints the counts; exit 0 when within the limits, 1
// otherwise, 2 on usage or read errors. Used by the package test to compare
// the example host's output with sinew-editor render.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "runtime/image/image_io.h"

int main(int argc, char** argv) {
  namespace cli = sinew::cli;
  cli::CommandLine line("sinew-image-diff",
                        "Compares the RGB channels of two 8-bit images (PNG, PPM, any format OpenImageIO\n"
                        "reads). Exit 0 when within the limits, 1 otherwise, 2 on usage or read errors.\n");
  const auto& images = line.positionals("IMAGE", "the two images A and B", 2);
  const auto& channel_text = line.option("--max-channel-diff", "N",
                                         "a pixel differs when a channel differs by more than N (default 0)");
  const auto& differing_text = line.option("--max-differing-pixels", "N", "pixels allowed to differ (default 0)");
  if (const auto done = cli::help_or_usage_error(line, line.parse({argv + 1, argv + argc}), std::cout, std::cerr)) {
    return *done;
  }
  if (images.size() != 2) {
    return cli::usage_error(line.program(),
                            sinew::invalid_argument("IMAGE", std::to_string(images.size()) + " given",
                                                    "expected two images, A and B"),
                            std::cerr);
  }
  int max_channel_diff = 0;
  long max_differing = 0;
  if (channel_text) {
    const auto n = cli::parse_int("--max-channel-diff", *channel_text, 0, 255);
    if (!n.ok()) return cli::usage_error(line.program(), n.status(), std::cerr);
    max_channel_diff = static_cast<int>(*n);
  }
  if (differing_text) {
    const auto n = cli::parse_int("--max-differing-pixels", *differing_text, 0, std::int64_t{1} << 40);
    if (!n.ok()) return cli::usage_error(line.program(), n.status(), std::cerr);
    max_differing = static_cast<long>(*n);
  }
  const auto a = sinew::read_image(images[0]);
  const auto b = sinew::read_image(images[1]);
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
