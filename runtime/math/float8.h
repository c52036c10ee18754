// Float8 / Mask8: eight float lanes as one value, so the renderer's SoA
// stages (ray generation, surface reconstruction, shading) read as the
// scalar formulas they evaluate. With AVX2 each operation is one
// instruction; in builds without AVX2 (the x86-64-v2 preset) the same code
// runs lane by lane. Every operation rounds exactly like the scalar one
// (IEEE add, sub, mul, div and sqrt; no fused multiply-add, see
// cmake/SinewCompilerOptions.cmake), so a lane reproduces scalar code bit
// for bit.
#pragma once

#include <cmath>
#include <bit>
#include <cstdint>
#include <limits>

#include "runtime/math/simd.h"

#if !SINEW_AVX2
#include <algorithm>
#endif

namespace sinew {

#if SINEW_AVX2

struct Mask8 {
  __m256 m;
  std::uint32_t bits() const { return static_cast<std::uint32_t>(_mm256_movemask_ps(m)); }
  bool any() const { return _mm256_testz_ps(m, m) == 0; }
  friend Mask8 operator&(Mask8 a, Mask8 b) { return {_mm256_and_ps(a.m, b.m)}; }
  friend Mask8 operator|(Mask8 a, Mask8 b) { return {_mm256_or_ps(a.m, b.m)}; }
  friend Mask8 operator!(Mask8 a) { return {_mm256_xor_ps(a.m, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))}; }
  // All-ones in the lanes of `bits` (bit i: lane i).
  static Mask8 from_bits(std::uint32_t bits) {
    const __m256i lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return {_mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), lane), lane))};
  }
};

struct Float8 {
  __m256 v;
  Float8() = default;
  Float8(__m256 x) : v(x) {}  // NOLINT: implicit from the native type
  Float8(float x) : v(_mm256_set1_ps(x)) {}  // NOLINT: implicit broadcast
  static Float8 load(const float* p) { return {_mm256_loadu_ps(p)}; }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
  // p[index[i]] per lane.
  static Float8 gather(const float* p, const std::uint32_t* index) {
    return {_mm256_i32gather_ps(p, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index)), 4)};
  }
  static Float8 lane_index() { return {_mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7)}; }

  friend Float8 operator+(Float8 a, Float8 b) { return {_mm256_add_ps(a.v, b.v)}; }
  friend Float8 operator-(Float8 a, Float8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
  friend Float8 operator*(Float8 a, Float8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
  friend Float8 operator/(Float8 a, Float8 b) { return {_mm256_div_ps(a.v, b.v)}; }
  friend Float8 operator-(Float8 a) { return {_mm256_xor_ps(a.v, _mm256_set1_ps(-0.0f))}; }
  friend Mask8 operator<(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
  friend Mask8 operator<=(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
  friend Mask8 operator>(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
  friend Mask8 operator>=(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GE_OQ)}; }
  friend Mask8 operator==(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
};

// a < b ? a : b and a > b ? a : b per lane (the second operand on NaN).
inline Float8 min(Float8 a, Float8 b) { return {_mm256_min_ps(a.v, b.v)}; }
inline Float8 max(Float8 a, Float8 b) { return {_mm256_max_ps(a.v, b.v)}; }
inline Float8 abs(Float8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.v)}; }
inline Float8 sqrt(Float8 a) { return {_mm256_sqrt_ps(a.v)}; }
// mask ? yes : no per lane.
inline Float8 select(Mask8 mask, Float8 yes, Float8 no) { return {_mm256_blendv_ps(no.v, yes.v, mask.m)}; }
// Lanes whose value is finite (not inf, not NaN).
inline Mask8 is_finite(Float8 a) {
  return {_mm256_cmp_ps(abs(a).v, _mm256_set1_ps(3.402823466e38f), _CMP_LE_OQ)};
}
// a * b + c rounded once, per lane, as std::fma: not the separate product
// and sum every other operation reproduces, so only for code that need not
// match scalar arithmetic bit for bit (a polynomial approximation).
inline Float8 fused_multiply_add(Float8 a, Float8 b, Float8 c) {
#if defined(__FMA__)
  return {_mm256_fmadd_ps(a.v, b.v, c.v)};
#else
  alignas(32) float x[8], y[8], z[8];
  _mm256_store_ps(x, a.v);
  _mm256_store_ps(y, b.v);
  _mm256_store_ps(z, c.v);
  for (int i = 0; i < 8; ++i) x[i] = std::fma(x[i], y[i], z[i]);
  return {_mm256_load_ps(x)};
#endif
}
// Truncation towards zero to int32, stored.
inline void store_truncated(Float8 a, std::int32_t* out) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_cvttps_epi32(a.v));
}
// p[i] = value in the lanes of `mask`, the others kept: eight 32-bit ids
// written beside the floats of the same lanes, without a branch per lane.
inline void store_where(Mask8 mask, std::uint32_t value, std::uint32_t* p) {
  __m256i* const q = reinterpret_cast<__m256i*>(p);
  const __m256i ids = _mm256_set1_epi32(static_cast<int>(value));
  _mm256_storeu_si256(q, _mm256_blendv_epi8(_mm256_loadu_si256(q), ids, _mm256_castps_si256(mask.m)));
}
// The smallest and the largest lane (no NaN lanes expected).
inline float reduce_min(Float8 a) {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(a.v), _mm256_extractf128_ps(a.v, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}
// The sum of the lanes: halves, then pairs.
inline float reduce_add(Float8 a) {
  __m128 m = _mm_add_ps(_mm256_castps256_ps128(a.v), _mm256_extractf128_ps(a.v, 1));
  m = _mm_add_ps(m, _mm_movehl_ps(m, m));
  m = _mm_add_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}
inline float reduce_max(Float8 a) {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(a.v), _mm256_extractf128_ps(a.v, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}

namespace detail {
// Per 8-bit mask, the lanes it selects packed to the front (a permutation).
struct CompressTable {
  alignas(32) std::int32_t index[256][8];
  CompressTable() {
    for (int m = 0; m < 256; ++m) {
      int n = 0;
      for (int i = 0; i < 8; ++i) {
        if (m >> i & 1) index[m][n++] = i;
      }
      for (; n < 8; ++n) index[m][n] = 0;
    }
  }
};
inline const CompressTable kCompressTable;
}  // namespace detail

// Writes the lanes of `mask` (bit i: lane i) to out[0 .. popcount - 1], in
// lane order; out must have room for eight (the rest is overwritten).
inline void compress_store(float* out, Float8 a, std::uint32_t mask) {
  const __m256i perm = _mm256_load_si256(reinterpret_cast<const __m256i*>(detail::kCompressTable.index[mask & 0xFFu]));
  _mm256_storeu_ps(out, _mm256_permutevar8x32_ps(a.v, perm));
}
// compress_store of the eight values base + lane, formed in a register (an
// array of them written lane by lane and loaded whole stalls on the
// store-to-load forward).
inline void compress_store_lane_indices(std::uint32_t* out, std::uint32_t base, std::uint32_t mask) {
  const __m256i lanes = _mm256_load_si256(reinterpret_cast<const __m256i*>(detail::kCompressTable.index[mask & 0xFFu]));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out),
                      _mm256_add_epi32(lanes, _mm256_set1_epi32(static_cast<int>(base))));
}

// Bit i set where values[i] == value, for eight values (unaligned).
inline std::uint32_t lanes_equal(const std::uint32_t* values, std::uint32_t value) {
  const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(values));
  const __m256i same = _mm256_cmpeq_epi32(v, _mm256_set1_epi32(static_cast<int>(value)));
  return static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(same)));
}

// Lanes i = p[i % 4]: four floats repeated.
inline Float8 repeat4(const float* p) { return {_mm256_broadcast_ps(reinterpret_cast<const __m128*>(p))}; }
// Lanes 0-3 lo, lanes 4-7 hi.
inline Float8 halves(float lo, float hi) { return {_mm256_insertf128_ps(_mm256_set1_ps(lo), _mm_set1_ps(hi), 1)}; }

// The next float from x away from zero offsets: towards +inf where
// offset > 0, towards -inf where offset < 0, x itself where offset is 0 or
// x is not finite; from zero, the smallest denormal.
inline Float8 step_away(Float8 x, Float8 offset) {
  const __m256i bits = _mm256_castps_si256(x.v);
  const Mask8 up = offset > Float8(0.0f);
  const Mask8 down = offset < Float8(0.0f);
  const Mask8 positive = x > Float8(0.0f);
  // (x > 0) == up: one ulp up in magnitude, else down.
  const __m256 grow = _mm256_xor_ps(_mm256_xor_ps(positive.m, up.m), _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
  const __m256i delta = _mm256_blendv_epi8(_mm256_set1_epi32(-1), _mm256_set1_epi32(1), _mm256_castps_si256(grow));
  Float8 stepped{_mm256_castsi256_ps(_mm256_add_epi32(bits, delta))};
  const Float8 denorm(std::numeric_limits<float>::denorm_min());
  stepped = select(x == Float8(0.0f), select(up, denorm, -denorm), stepped);
  return select((up | down) & is_finite(x), stepped, x);
}

#else  // lane by lane

struct Mask8 {
  std::uint32_t b = 0;
  std::uint32_t bits() const { return b; }
  bool any() const { return b != 0; }
  friend Mask8 operator&(Mask8 a, Mask8 c) { return {a.b & c.b}; }
  friend Mask8 operator|(Mask8 a, Mask8 c) { return {a.b | c.b}; }
  friend Mask8 operator!(Mask8 a) { return {~a.b & 0xFFu}; }
  static Mask8 from_bits(std::uint32_t bits) { return {bits & 0xFFu}; }
};

struct Float8 {
  float v[8];
  Float8() = default;
  Float8(float x) {  // NOLINT: implicit broadcast
    for (float& e : v) e = x;
  }
  static Float8 load(const float* p) {
    Float8 r;
    for (int i = 0; i < 8; ++i) r.v[i] = p[i];
    return r;
  }
  void store(float* p) const {
    for (int i = 0; i < 8; ++i) p[i] = v[i];
  }
  static Float8 gather(const float* p, const std::uint32_t* index) {
    Float8 r;
    for (int i = 0; i < 8; ++i) r.v[i] = p[index[i]];
    return r;
  }
  static Float8 lane_index() {
    Float8 r;
    for (int i = 0; i < 8; ++i) r.v[i] = static_cast<float>(i);
    return r;
  }
  template <class Fn>
  static Float8 map(Fn fn) {
    Float8 r;
    for (int i = 0; i < 8; ++i) r.v[i] = fn(i);
    return r;
  }
  template <class Fn>
  static Mask8 test(Fn fn) {
    Mask8 m;
    for (int i = 0; i < 8; ++i) m.b |= fn(i) ? (1u << i) : 0u;
    return m;
  }
  friend Float8 operator+(Float8 a, Float8 b) { return map([&](int i) { return a.v[i] + b.v[i]; }); }
  friend Float8 operator-(Float8 a, Float8 b) { return map([&](int i) { return a.v[i] - b.v[i]; }); }
  friend Float8 operator*(Float8 a, Float8 b) { return map([&](int i) { return a.v[i] * b.v[i]; }); }
  friend Float8 operator/(Float8 a, Float8 b) { return map([&](int i) { return a.v[i] / b.v[i]; }); }
  friend Float8 operator-(Float8 a) { return map([&](int i) { return -a.v[i]; }); }
  friend Mask8 operator<(Float8 a, Float8 b) { return test([&](int i) { return a.v[i] < b.v[i]; }); }
  friend Mask8 operator<=(Float8 a, Float8 b) { return test([&](int i) { return a.v[i] <= b.v[i]; }); }
  friend Mask8 operator>(Float8 a, Float8 b) { return test([&](int i) { return a.v[i] > b.v[i]; }); }
  friend Mask8 operator>=(Float8 a, Float8 b) { return test([&](int i) { return a.v[i] >= b.v[i]; }); }
  friend Mask8 operator==(Float8 a, Float8 b) { return test([&](int i) { return a.v[i] == b.v[i]; }); }
};

inline Float8 min(Float8 a, Float8 b) { return Float8::map([&](int i) { return a.v[i] < b.v[i] ? a.v[i] : b.v[i]; }); }
inline Float8 max(Float8 a, Float8 b) { return Float8::map([&](int i) { return a.v[i] > b.v[i] ? a.v[i] : b.v[i]; }); }
inline Float8 abs(Float8 a) { return Float8::map([&](int i) { return std::fabs(a.v[i]); }); }
inline Float8 sqrt(Float8 a) { return Float8::map([&](int i) { return std::sqrt(a.v[i]); }); }
inline Float8 select(Mask8 mask, Float8 yes, Float8 no) {
  return Float8::map([&](int i) { return (mask.b >> i & 1u) ? yes.v[i] : no.v[i]; });
}
inline Mask8 is_finite(Float8 a) { return Float8::test([&](int i) { return std::isfinite(a.v[i]); }); }
inline Float8 fused_multiply_add(Float8 a, Float8 b, Float8 c) {
  return Float8::map([&](int i) { return std::fma(a.v[i], b.v[i], c.v[i]); });
}
inline void store_truncated(Float8 a, std::int32_t* out) {
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::int32_t>(a.v[i]);
}
inline void store_where(Mask8 mask, std::uint32_t value, std::uint32_t* p) {
  for (int i = 0; i < 8; ++i) {
    if (mask.b >> i & 1u) p[i] = value;
  }
}
inline float reduce_min(Float8 a) {
  float m = a.v[0];
  for (int i = 1; i < 8; ++i) m = a.v[i] < m ? a.v[i] : m;
  return m;
}
// The AVX2 reduce_add's order: halves, then pairs.
inline float reduce_add(Float8 a) {
  const auto& v = a.v;
  return ((v[0] + v[4]) + (v[2] + v[6])) + ((v[1] + v[5]) + (v[3] + v[7]));
}
inline float reduce_max(Float8 a) {
  float m = a.v[0];
  for (int i = 1; i < 8; ++i) m = a.v[i] > m ? a.v[i] : m;
  return m;
}
inline void compress_store(float* out, Float8 a, std::uint32_t mask) {
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    if (mask >> i & 1u) out[n++] = a.v[i];
  }
}
inline void compress_store_lane_indices(std::uint32_t* out, std::uint32_t base, std::uint32_t mask) {
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    if (mask >> i & 1u) out[n++] = base + static_cast<std::uint32_t>(i);
  }
}
inline std::uint32_t lanes_equal(const std::uint32_t* values, std::uint32_t value) {
  std::uint32_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= values[i] == value ? 1u << i : 0u;
  return bits;
}

inline Float8 repeat4(const float* p) { return Float8::map([&](int i) { return p[i % 4]; }); }
inline Float8 halves(float lo, float hi) { return Float8::map([&](int i) { return i < 4 ? lo : hi; }); }
inline Float8 step_away(Float8 x, Float8 offset) {
  return Float8::map([&](int i) {
    const float v = x.v[i];
    const float o = offset.v[i];
    if (o == 0.0f || !std::isfinite(v)) return v;
    const bool up = o > 0.0f;
    if (v == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
    std::uint32_t b = std::bit_cast<std::uint32_t>(v);
    b = (v > 0.0f) == up ? b + 1 : b - 1;
    return std::bit_cast<float>(b);
  });
}

#endif

// Vectors of eight lanes, structure of arrays.
struct Vec3x8 {
  Float8 x, y, z;
};
inline Vec3x8 operator+(const Vec3x8& a, const Vec3x8& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3x8 operator-(const Vec3x8& a, const Vec3x8& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3x8 operator*(Float8 s, const Vec3x8& a) { return {s * a.x, s * a.y, s * a.z}; }
// glm::dot's order: (x*x + y*y) + z*z.
inline Float8 dot(const Vec3x8& a, const Vec3x8& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
// glm::cross's expressions.
inline Vec3x8 cross(const Vec3x8& a, const Vec3x8& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
inline Vec3x8 select(Mask8 m, const Vec3x8& yes, const Vec3x8& no) {
  return {select(m, yes.x, no.x), select(m, yes.y, no.y), select(m, yes.z, no.z)};
}

}  // namespace sinew
