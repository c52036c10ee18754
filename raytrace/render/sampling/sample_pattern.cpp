#include "raytrace/render/sampling/sample_pattern.h"

#include <cmath>
#include <numbers>

namespace sinew::rt {
namespace {

// An integer mix with full avalanche (two multiply-xorshift rounds): every
// input bit flips each output bit about half the time, so neighbouring
// pixels get unrelated shifts.
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

PixelShift pixel_shift(std::uint32_t seed, std::uint32_t stream, int x, int y) {
  const std::uint32_t h = mix(mix(mix(mix(static_cast<std::uint32_t>(y)) ^ static_cast<std::uint32_t>(x)) ^ stream) ^ seed);
  const std::uint32_t step = mix(h) >> (32 - 10);  // kAngleSteps = 2^10
  static_assert(kAngleSteps == 1 << 10);
  PixelShift shift;
  shift.xi = fraction(h, 24);
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
