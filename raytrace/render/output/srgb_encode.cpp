#include "raytrace/render/output/srgb_encode.h"

#include "raytrace/render/output/srgb.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/math/float8.h"

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SINEW_SRGB_AVX512 1
#else
#define SINEW_SRGB_AVX512 0
#endif

namespace sinew::rt {

void srgb_encode_8(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count) {
  for (std::size_t i = 0; i < count; i += 8) {
    alignas(32) std::int32_t red[8], green[8], blue[8];
    store_truncated(srgb_steps(Float8::load(r + i)), red);
    store_truncated(srgb_steps(Float8::load(g + i)), green);
    store_truncated(srgb_steps(Float8::load(b + i)), blue);
    for (int lane = 0; lane < 8; ++lane) {
      rgba[i + static_cast<std::size_t>(lane)] = static_cast<std::uint32_t>(red[lane]) |
                                                 static_cast<std::uint32_t>(green[lane]) << 8 |
                                                 static_cast<std::uint32_t>(blue[lane]) << 16 | 0xFF000000u;
    }
  }
}

#if SINEW_SRGB_AVX512

// GCC 12's AVX-512 min/max intrinsics pass _mm512_undefined_ps() as the
// unused merge source, which -Wmaybe-uninitialized reports once inlined.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace {

// srgb_steps, sixteen lanes: the same operations in the same order (a
// product and a sum where it has them, fused where it fuses), so the same
// bits. The table of ten is one permute here, where eight lanes need two
// and a blend.
[[gnu::target("avx512f")]] inline __m512 srgb_steps_16(__m512 linear) {
  const __m512 c = _mm512_min_ps(_mm512_max_ps(linear, _mm512_setzero_ps()), _mm512_set1_ps(1.0f));
  const __m512 toe = _mm512_add_ps(_mm512_mul_ps(c, _mm512_set1_ps(12.92f * 255.0f)), _mm512_set1_ps(0.5f));
  const __m512i bits = _mm512_castps_si512(_mm512_max_ps(c, _mm512_set1_ps(kSrgbToe)));
  const __m512i index = _mm512_sub_epi32(_mm512_srli_epi32(bits, 23), _mm512_set1_epi32(127 - 9));
  const __m512 m = _mm512_castsi512_ps(
      _mm512_or_si512(_mm512_and_si512(bits, _mm512_set1_epi32(0x007FFFFF)), _mm512_set1_epi32(0x3F800000)));
  const __m512 scale = _mm512_permutexvar_ps(index, _mm512_loadu_ps(kSrgbScale));
  const __m512 t = _mm512_sub_ps(m, _mm512_set1_ps(1.0f));
  const __m512 t2 = _mm512_mul_ps(t, t);
  const __m512 p01 = _mm512_fmadd_ps(_mm512_set1_ps(kSrgbM[1]), t, _mm512_set1_ps(kSrgbM[0]));
  const __m512 p23 = _mm512_fmadd_ps(_mm512_set1_ps(kSrgbM[3]), t, _mm512_set1_ps(kSrgbM[2]));
  const __m512 p45 = _mm512_fmadd_ps(_mm512_set1_ps(kSrgbM[5]), t, _mm512_set1_ps(kSrgbM[4]));
  const __m512 root = _mm512_fmadd_ps(_mm512_fmadd_ps(p45, t2, p23), t2, p01);
  const __m512 curve = _mm512_fmadd_ps(scale, root, _mm512_set1_ps(kSrgbOffset));
  return _mm512_mask_blend_ps(_mm512_cmp_ps_mask(c, _mm512_set1_ps(kSrgbToe), _CMP_LE_OQ), curve, toe);
}

}  // namespace

[[gnu::target("avx512f")]] void srgb_encode_16(const float* r, const float* g, const float* b,
                                               std::uint32_t* rgba, std::size_t count) {
  for (std::size_t i = 0; i < count; i += 16) {
    const __m512i red = _mm512_cvttps_epi32(srgb_steps_16(_mm512_loadu_ps(r + i)));
    const __m512i green = _mm512_cvttps_epi32(srgb_steps_16(_mm512_loadu_ps(g + i)));
    const __m512i blue = _mm512_cvttps_epi32(srgb_steps_16(_mm512_loadu_ps(b + i)));
    const __m512i pixels =
        _mm512_or_si512(_mm512_or_si512(red, _mm512_slli_epi32(green, 8)),
                        _mm512_or_si512(_mm512_slli_epi32(blue, 16), _mm512_set1_epi32(static_cast<int>(0xFF000000u))));
    _mm512_storeu_si512(rgba + i, pixels);
  }
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool srgb_encode_16_available() {
  static const bool available = detect_cpu_features().avx512f;
  return available;
}

#else

void srgb_encode_16(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count) {
  srgb_encode_8(r, g, b, rgba, count);  // never chosen: no AVX-512 here
}

bool srgb_encode_16_available() { return false; }

#endif

void srgb_encode(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count) {
  if (srgb_encode_16_available()) {
    srgb_encode_16(r, g, b, rgba, count);
  } else {
    srgb_encode_8(r, g, b, rgba, count);
  }
}

const char* srgb_encode_path() {
  if (srgb_encode_16_available()) return "avx512";
  return SINEW_AVX2 ? "avx2" : "scalar";
}

}  // namespace sinew::rt
