// Linear -> sRGB bytes (IEC 61966-2-1), eight lanes at a time.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>

#include "runtime/math/float8.h"

namespace sinew::rt {

// By arithmetic: std::pow per
// channel cost more than the shading itself, and a byte table's three
// gathers per eight pixels were a quarter of shade_and_write. Above the
// curve's linear toe (c > 0.0031308), 255 * (1.055 c^(1/2.4) - 0.055) splits
// c = 2^e m (e from -9 to 0, m in [1, 2)): c^(1/2.4) = 2^(e/2.4) m^(1/2.4),
// the first factor (times 255 * 1.055) from a table of ten, the second a
// degree-5 polynomial in m - 1 (Chebyshev interpolation, 1.8e-6 relative
// at most). In real arithmetic that is 0.0005 of a byte step off the curve
// at most; in float 0.0004 was the worst over every 97th float in [0, 1].
// So a byte is off the correctly rounded one by at most one step, and only
// where the exact value lies within 0.001 of a half step
// (Srgb.BytesAreTheCorrectlyRoundedCurveButAtHalfSteps checks that against
// the curve in double). The 0.5 added rounds by truncation. Lanes not > 0
// (NaN too) give 0; lanes above 1 give 255 (a value of at most 255.5005).
// It replaced c^(1/4) by two square roots and a polynomial in that: the
// square roots' throughput was most of the encoding's cost. Each of its
// operations counts: the encoding is a large share of the shading
// (docs/RAYTRACE.md, "sRGB bytes").
inline constexpr float kSrgbScale[16] = {  // 255 * 1.055 * 2^(e/2.4), e = -9 .. 0
    19.9954033f, 26.6906605f, 35.627758f, 47.5573502f, 63.4814453f, 84.7375641f, 113.111076f, 150.985184f,
    201.541031f, 269.024994f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
inline constexpr float kSrgbM[6] = {1.000001767f, 0.4165380931f, -0.1199465989f, 0.05661427386f, -0.02351015063f,
                             0.005143488095f};  // m^(1/2.4) ~ sum kSrgbM[i] (m - 1)^i
inline constexpr float kSrgbToe = 0.0031308f;
inline constexpr float kSrgbOffset = -255.0f * 0.055f + 0.5f;

// Each lane's byte plus a fraction (truncate to get the byte).
inline Float8 srgb_steps(Float8 linear) {
#if SINEW_AVX2
  // maxps takes its second operand, zero, where the first is NaN.
  const Float8 c = min(Float8{_mm256_max_ps(linear.v, _mm256_setzero_ps())}, Float8(1.0f));
#else
  const Float8 c = min(select(linear > Float8(0.0f), linear, Float8(0.0f)), Float8(1.0f));
#endif
  const Float8 toe = c * Float8(12.92f * 255.0f) + Float8(0.5f);
#if SINEW_AVX2
  const __m256i bits = _mm256_castps_si256(max(c, Float8(kSrgbToe)).v);
  // e + 9 (the exponent's bias is 127), and m - 1 from m's bits.
  const __m256i index = _mm256_sub_epi32(_mm256_srli_epi32(bits, 23), _mm256_set1_epi32(127 - 9));
  const Float8 m{_mm256_castsi256_ps(
      _mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi32(0x007FFFFF)), _mm256_set1_epi32(0x3F800000)))};
  const __m256 low = _mm256_permutevar8x32_ps(_mm256_loadu_ps(kSrgbScale), index);
  const __m256 high = _mm256_permutevar8x32_ps(_mm256_loadu_ps(kSrgbScale + 8), index);
  // The index is 0 to 9: its bit 3, shifted into the sign, picks the table.
  const Float8 scale{_mm256_blendv_ps(low, high, _mm256_castsi256_ps(_mm256_slli_epi32(index, 28)))};
  const Float8 t = m - Float8(1.0f);
#else
  const Float8 scale = Float8::map([&](int i) {
    const float x = std::max(c.v[i], kSrgbToe);
    return kSrgbScale[(std::bit_cast<std::uint32_t>(x) >> 23) - (127 - 9)];
  });
  const Float8 t = Float8::map([&](int i) {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(std::max(c.v[i], kSrgbToe));
    return std::bit_cast<float>((bits & 0x007FFFFFu) | 0x3F800000u) - 1.0f;
  });
#endif
  // Estrin's order: three dependent steps.
  const Float8 t2 = t * t;
  const Float8 p01 = fused_multiply_add(Float8(kSrgbM[1]), t, Float8(kSrgbM[0]));
  const Float8 p23 = fused_multiply_add(Float8(kSrgbM[3]), t, Float8(kSrgbM[2]));
  const Float8 p45 = fused_multiply_add(Float8(kSrgbM[5]), t, Float8(kSrgbM[4]));
  const Float8 root = fused_multiply_add(fused_multiply_add(p45, t2, p23), t2, p01);
  const Float8 curve = fused_multiply_add(scale, root, Float8(kSrgbOffset));
  // At c = 1 the curve is 255.5005 (under 256, so no clamp: it truncates
  // to 255).
  return select(c <= Float8(kSrgbToe), toe, curve);
}
inline std::uint8_t srgb_byte(float linear) {
  alignas(32) std::int32_t steps[8];
  store_truncated(srgb_steps(Float8(linear)), steps);
  return static_cast<std::uint8_t>(steps[0]);
}

// Eight RGBA8 pixels, R in the low byte, alpha 255.
[[gnu::always_inline]] inline void srgb_rgba8(const Vec3x8& linear, std::uint32_t* out) {
#if SINEW_AVX2
  const auto bytes = [](Float8 x) { return _mm256_cvttps_epi32(srgb_steps(x).v); };
  const __m256i rgba = _mm256_or_si256(
      _mm256_or_si256(bytes(linear.x), _mm256_slli_epi32(bytes(linear.y), 8)),
      _mm256_or_si256(_mm256_slli_epi32(bytes(linear.z), 16), _mm256_set1_epi32(static_cast<int>(0xFF000000u))));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), rgba);
#else
  alignas(32) std::int32_t r[8], g[8], b[8];
  store_truncated(srgb_steps(linear.x), r);
  store_truncated(srgb_steps(linear.y), g);
  store_truncated(srgb_steps(linear.z), b);
  for (int i = 0; i < 8; ++i) {
    out[i] = static_cast<std::uint32_t>(r[i]) | static_cast<std::uint32_t>(g[i]) << 8 |
             static_cast<std::uint32_t>(b[i]) << 16 | 0xFF000000u;
  }
#endif
}

}  // namespace sinew::rt
