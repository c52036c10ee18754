// sinew-frame-check IMAGE [--turn 0|90|180]: is there one upright, framed
// figure in the image? Used by the package.minimal_* tests on
// examples/minimal's output, which draws one character and no ground on a
// plain background.
//
// The background is the colour most of the border's pixels have; a pixel
// is the figure's when a channel differs from it by more than 8. Checks:
//   * not empty: the figure covers at least 1% of the image;
//   * framed: no figure pixel on the border, and it covers at most 60%;
//   * upright: its silhouette is at least 0.8 times as tall as wide (a
//     figure seen standing from the front, arms spread or not; seen along
//     its length, as a camera with the wrong up axis sees it, it is far
//     shorter than wide), and its pixels' centroid lies above the
//     silhouette's middle row (legs below a heavier body; a figure upside
//     down has its centroid below).
// --turn turns the image by 90 or 180 degrees first: the tests check that
// the figure lying on its side or upside down is refused, so the check can
// fail.
// Prints the figures; exit 0 when all hold, 1 naming the first that does
// not, 2 on usage or read errors.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "runtime/image/image_io.h"

int main(int argc, char** argv) {
  namespace cli = sinew::cli;
  cli::CommandLine line("sinew-frame-check",
                        "Checks that an 8-bit RGB image (PPM, PNG) shows one figure, upright and framed,\n"
                        "on a plain background. Exit 0 when it does, 1 otherwise, 2 on usage or read errors.\n");
  const auto& images = line.positionals("IMAGE", "the image", 1);
  const auto& turn_text = line.option("--turn", "0|90|180", "turn the image clockwise first (default 0)");
  if (const auto done = cli::help_or_usage_error(line, line.parse({argv + 1, argv + argc}), std::cout, std::cerr)) {
    return *done;
  }
  if (images.size() != 1) {
    return cli::usage_error(line.program(), sinew::invalid_argument("IMAGE", "", "expected one image"), std::cerr);
  }
  int turn = 0;
  if (turn_text) {
    const auto c = cli::parse_choice("--turn", *turn_text, {"0", "90", "180"});
    if (!c.ok()) return cli::usage_error(line.program(), c.status(), std::cerr);
    turn = *c;
  }
  const auto image = sinew::read_image(images[0]);
  if (!image.ok()) {
    std::fprintf(stderr, "sinew-frame-check: %s\n", image.status().message().c_str());
    return 2;
  }
  if (image->desc.type != sinew::PixelType::kU8 || image->desc.channels < 3 || image->desc.width < 8 ||
      image->desc.height < 8) {
    std::fprintf(stderr, "sinew-frame-check: expected an 8-bit RGB image of at least 8x8 pixels\n");
    return 2;
  }
  const int iw = image->desc.width;
  const int ih = image->desc.height;
  const int channels = image->desc.channels;
  const auto px = image->as<std::uint8_t>();
  const auto source = [&](int x, int y) {
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(iw) + static_cast<std::size_t>(x)) *
                          static_cast<std::size_t>(channels);
    return (int(px[i]) << 16) | (int(px[i + 1]) << 8) | int(px[i + 2]);
  };
  // The image as checked: turned clockwise by 0, 90 or 180 degrees.
  const int w = turn == 1 ? ih : iw;
  const int h = turn == 1 ? iw : ih;
  const auto rgb = [&](int x, int y) {
    if (turn == 1) return source(y, ih - 1 - x);
    if (turn == 2) return source(iw - 1 - x, ih - 1 - y);
    return source(x, y);
  };
  const auto on_border = [&](int x, int y) { return x == 0 || y == 0 || x == w - 1 || y == h - 1; };

  // The background: the border's most common colour.
  std::map<int, int> border_colours;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (on_border(x, y)) ++border_colours[rgb(x, y)];
    }
  }
  const int background =
      std::max_element(border_colours.begin(), border_colours.end(),
                       [](const auto& a, const auto& b) { return a.second < b.second; })->first;
  const auto is_figure = [&](int x, int y) {
    const int c = rgb(x, y);
    for (int shift : {16, 8, 0}) {
      if (std::abs(((c >> shift) & 255) - ((background >> shift) & 255)) > 8) return true;
    }
    return false;
  };

  long figure = 0, on_edge = 0;
  double row_sum = 0.0;
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!is_figure(x, y)) continue;
      ++figure;
      row_sum += y;
      on_edge += on_border(x, y);
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  const double coverage = static_cast<double>(figure) / (static_cast<double>(w) * h);
  std::printf("sinew-frame-check: %s: %dx%d, background #%06x, figure %ld pixels (%.1f%%)", images[0].c_str(), w, h,
              background, figure, 100.0 * coverage);
  if (figure == 0) {
    std::printf("\nsinew-frame-check: FAILED: the image is empty (nothing but the background)\n");
    return 1;
  }
  const int sw = x1 - x0 + 1;
  const int sh = y1 - y0 + 1;
  // The centroid's height above the silhouette's lowest row, as a fraction
  // of its height (rows grow downwards).
  const double centroid = (y1 - row_sum / static_cast<double>(figure)) / std::max(1, sh - 1);
  std::printf(", silhouette %dx%d at (%d,%d)-(%d,%d), %ld on the border, centroid at %.3f of its height\n", sw, sh,
              x0, y0, x1, y1, on_edge, centroid);
  const char* failed = nullptr;
  if (coverage < 0.01) {
    failed = "not a figure: it covers less than 1% of the image";
  } else if (on_edge > 0) {
    failed = "not framed: the figure touches the image's border";
  } else if (coverage > 0.6) {
    failed = "not framed: the figure covers more than 60% of the image";
  } else if (sh < 0.8 * sw) {
    failed = "not upright: the silhouette is not at least 0.8 times as tall as wide";
  } else if (!(centroid > 0.5)) {
    failed = "not upright: the figure's centroid is not above its middle row";
  }
  if (failed != nullptr) {
    std::printf("sinew-frame-check: FAILED: %s\n", failed);
    return 1;
  }
  std::printf("sinew-frame-check: one upright, framed figure\n");
  return 0;
}
