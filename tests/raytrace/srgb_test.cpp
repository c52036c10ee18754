// The sRGB encoding (render/output/srgb.h) against IEC 61966-2-1's curve in
// double: every 97th float of [0, 1] gets the correctly rounded byte, or one
// step off only where the exact value lies within 0.001 of a half step; the
// toe, the clamps and NaN. The many-pixel encoder (render/output/srgb_encode.h)
// gives those bytes on each of its paths.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "raytrace/render/output/srgb.h"
#include "raytrace/render/output/srgb_encode.h"

namespace sinew {
namespace {

double exact_steps(double c) {
  return c <= 0.0031308 ? 255.0 * 12.92 * c : 255.0 * (1.055 * std::pow(c, 1.0 / 2.4) - 0.055);
}

TEST(Srgb, BytesAreTheCorrectlyRoundedCurveButAtHalfSteps) {
  std::uint64_t checked = 0, off = 0;
  double worst = 0.0;
  for (std::uint32_t bits = 0; bits <= std::bit_cast<std::uint32_t>(1.0f); bits += 97) {
    const float c = std::bit_cast<float>(bits);
    alignas(32) float steps[8];
    rt::srgb_steps(Float8(c)).store(steps);
    const double exact = exact_steps(c);
    // Before the truncation: the curve plus one half.
    worst = std::max(worst, std::fabs((static_cast<double>(steps[0]) - 0.5) - exact));
    const int byte = rt::srgb_byte(c);
    const int rounded = static_cast<int>(std::floor(exact + 0.5));
    ++checked;
    if (byte == rounded) continue;
    ++off;
    ASSERT_EQ(std::abs(byte - rounded), 1) << c;
    ASSERT_LT(std::fabs(exact - std::floor(exact) - 0.5), 0.001) << c << ": off a step away from a half step";
  }
  EXPECT_GT(checked, 10'000'000u);
  EXPECT_LT(worst, 0.001) << "of a byte step";
  EXPECT_LT(off, checked / 1000);
}

TEST(Srgb, ClampsAndTheToe) {
  EXPECT_EQ(rt::srgb_byte(0.0f), 0);
  EXPECT_EQ(rt::srgb_byte(-1.0f), 0);
  EXPECT_EQ(rt::srgb_byte(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(rt::srgb_byte(1.0f), 255);
  EXPECT_EQ(rt::srgb_byte(7.5f), 255);
  EXPECT_EQ(rt::srgb_byte(std::numeric_limits<float>::infinity()), 255);
  // The linear toe: 255 * 12.92 * c, rounded (0.002 -> 6.59 -> 7).
  EXPECT_EQ(rt::srgb_byte(0.002f), 7);
  // On the curve: 255 * (1.055 * 0.2^(1/2.4) - 0.055) = 123.55 -> 124.
  EXPECT_EQ(rt::srgb_byte(0.2f), 124);
}

// Channel values the encoder must handle: every 4099th float of [0, 1] (its
// toe and curve, with denormals), the edges, values past the clamps, NaN
// and infinities, padded to whole groups of sixteen.
std::vector<float> encoder_inputs() {
  std::vector<float> values;
  for (std::uint32_t bits = 0; bits <= std::bit_cast<std::uint32_t>(1.0f); bits += 4099) {
    values.push_back(std::bit_cast<float>(bits));
  }
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  for (const float c : {0.0f, -0.0f, -1.0f, -kInf, kInf, kNaN, -kNaN, 1.0f, std::nextafter(1.0f, 2.0f), 7.5f,
                        0.0031308f, std::nextafter(0.0031308f, 0.0f), std::nextafter(0.0031308f, 1.0f), 0.2f,
                        std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()}) {
    values.push_back(c);
  }
  while (values.size() % rt::kSrgbEncodeLanes != 0) values.push_back(0.5f);
  return values;
}

// Pixel i's channels: value i, value i + 1 and value i + 2 (wrapping), so
// each value lands in every channel and lane position.
struct EncoderCase {
  std::vector<float> r, g, b;
  explicit EncoderCase(const std::vector<float>& v) : r(v), g(v.size()), b(v.size()) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      g[i] = v[(i + 1) % v.size()];
      b[i] = v[(i + 2) % v.size()];
    }
  }
  std::uint32_t expected(std::size_t i) const {
    return static_cast<std::uint32_t>(rt::srgb_byte(r[i])) | static_cast<std::uint32_t>(rt::srgb_byte(g[i])) << 8 |
           static_cast<std::uint32_t>(rt::srgb_byte(b[i])) << 16 | 0xFF000000u;
  }
};

TEST(SrgbEncode, EightLanesGiveTheBytesOfTheCurve) {
  const EncoderCase c(encoder_inputs());
  std::vector<std::uint32_t> rgba(c.r.size(), 0u);
  rt::srgb_encode_8(c.r.data(), c.g.data(), c.b.data(), rgba.data(), rgba.size());
  for (std::size_t i = 0; i < rgba.size(); ++i) ASSERT_EQ(rgba[i], c.expected(i)) << "pixel " << i << " r " << c.r[i];
  EXPECT_GT(rgba.size(), 250'000u);
}

// The encoder the renderer calls gives the eight-lane path's bytes, and
// takes the sixteen-lane path exactly where the CPU has AVX-512F, whose
// bytes are then the eight-lane path's too, bit for bit.
TEST(SrgbEncode, ThePathTheCpuTakesGivesTheBytesOfEightLanes) {
  const EncoderCase c(encoder_inputs());
  std::vector<std::uint32_t> eight(c.r.size(), 0u), chosen(c.r.size(), 0u);
  rt::srgb_encode_8(c.r.data(), c.g.data(), c.b.data(), eight.data(), eight.size());
  rt::srgb_encode(c.r.data(), c.g.data(), c.b.data(), chosen.data(), chosen.size());
  for (std::size_t i = 0; i < eight.size(); ++i) {
    ASSERT_EQ(chosen[i], eight[i]) << "pixel " << i << " r " << c.r[i] << " g " << c.g[i] << " b " << c.b[i];
  }
  const bool wide = rt::srgb_encode_16_available();
  EXPECT_EQ(std::string(rt::srgb_encode_path()) == "avx512", wide);
  if (wide) {
    std::vector<std::uint32_t> sixteen(c.r.size(), 0u);
    rt::srgb_encode_16(c.r.data(), c.g.data(), c.b.data(), sixteen.data(), sixteen.size());
    EXPECT_EQ(sixteen, eight);
  }
}

// The encoder writes exactly count pixels, from any starting lane.
TEST(SrgbEncode, WritesCountPixelsAndNoMore) {
  const EncoderCase c(encoder_inputs());
  for (const std::size_t offset : {std::size_t{0}, std::size_t{8}, std::size_t{5}}) {
    std::vector<std::uint32_t> rgba(offset + 3 * rt::kSrgbEncodeLanes, 0xA5A5A5A5u);
    rt::srgb_encode(c.r.data() + offset, c.g.data() + offset, c.b.data() + offset, rgba.data() + offset,
                    2 * rt::kSrgbEncodeLanes);
    for (std::size_t i = 0; i < rgba.size(); ++i) {
      if (i < offset || i >= offset + 2 * rt::kSrgbEncodeLanes) {
        ASSERT_EQ(rgba[i], 0xA5A5A5A5u) << i;
      } else {
        ASSERT_EQ(rgba[i], c.expected(i)) << i;
      }
    }
  }
}

}  // namespace
}  // namespace sinew
