#include "raytrace/render/sampling/sample_pattern.h"

#include <cmath>
#include <numbers>

namespace sinew::rt {
namespace {

// An integer mix with full avalanche (two multiply-xorshift rounds): every
// input bit flips each output bit about half the time, so seeds and
// streams get unrelated offsets.
std::uint32_t mix(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// 1 - 1/phi: the lattice's step along v. Successive multiples of it stay
// as evenly spread over [0, 1) as any sequence can.
constexpr double kGolden = 0.38196601125010515;

struct AngleTable {
  std::array<float, kAngleSteps> cos_of{}, sin_of{};
  AngleTable() {
    for (int i = 0; i < kAngleSteps; ++i) {
      const double angle = 2.0 * std::numbers::pi * static_cast<double>(i) / kAngleSteps;
      cos_of[static_cast<std::size_t>(i)] = static_cast<float>(std::cos(angle));
      sin_of[static_cast<std::size_t>(i)] = static_cast<float>(std::sin(angle));
    }
  }
};
const AngleTable& angles() {
  static const AngleTable table;
  return table;
}

float fraction(std::uint32_t bits, int count) {
  return static_cast<float>(bits >> (32 - count)) * std::ldexp(1.0f, -count);
}

}  // namespace

int sample_class(int x, int y) {
  // A 2x2 ordered-dither (Bayer) matrix: classes 0 and 1 on one diagonal,
  // 2 and 3 on the other.
  static constexpr int kBayer[kInterleave][kInterleave] = {{0, 2}, {3, 1}};
  return kBayer[y & (kInterleave - 1)][x & (kInterleave - 1)];
}

PixelShift pixel_shift(std::uint32_t seed, std::uint32_t stream, int x, int y) {
  static_assert(kAngleSteps == 1 << 10 && kSampleClasses == 4);
  const std::uint32_t h = mix(mix(stream) ^ seed);
  const int k = sample_class(x, y);
  // The classes' shifts are the four-point Hammersley set of the unit
  // square, (k / 4, k's two bits reversed / 4), one point per quadrant,
  // moved as a whole by one hashed offset.
  static constexpr std::uint32_t kReversed[kSampleClasses] = {0u, 2u, 1u, 3u};
  const std::uint32_t step =
      ((mix(h) >> (32 - 10)) + (kAngleSteps / kSampleClasses) * kReversed[k]) & (kAngleSteps - 1u);
  PixelShift shift;
  // 20 bits: k + the fraction stays below kSampleClasses in a float, so xi below 1.
  shift.xi = (static_cast<float>(k) + fraction(h, 20)) / static_cast<float>(kSampleClasses);
  shift.eta = static_cast<float>(step) / kAngleSteps;
  shift.cos_eta = angles().cos_of[step];
  shift.sin_eta = angles().sin_of[step];
  return shift;
}

LatticeSample lattice_sample(int j) {
  const double v0 = std::fmod(static_cast<double>(j) * kGolden, 1.0);
  const double angle = 2.0 * std::numbers::pi * v0;
  return {static_cast<float>(v0), static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle))};
}

Vec2 square_sample(const PixelShift& shift, int j, int n) {
  const LatticeSample base = lattice_sample(j);
  const float v = base.v0 + shift.eta;
  return {(static_cast<float>(j) + shift.xi) / static_cast<float>(n), v >= 1.0f ? v - 1.0f : v};
}

Vec2 disk_sample(const PixelShift& shift, int j, int n) {
  const LatticeSample base = lattice_sample(j);
  const float r = std::sqrt((static_cast<float>(j) + shift.xi) / static_cast<float>(n));
  return {r * (base.cos_v0 * shift.cos_eta - base.sin_v0 * shift.sin_eta),
          r * (base.sin_v0 * shift.cos_eta + base.cos_v0 * shift.sin_eta)};
}

}  // namespace sinew::rt
