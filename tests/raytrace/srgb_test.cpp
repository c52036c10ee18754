// The sRGB encoding (render/srgb.h) against IEC 61966-2-1's curve in
// double: every 97th float of [0, 1] gets the correctly rounded byte, or one
// step off only where the exact value lies within 0.001 of a half step; the
// toe, the clamps and NaN.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "raytrace/render/srgb.h"

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

}  // namespace
}  // namespace sinew
