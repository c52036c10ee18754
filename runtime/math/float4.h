// Float4 / Mask4: four float lanes as one value, for the per-axis interval
// arithmetic of the ray-set bounds (cull/interval_bound.h, cull/ray_bound.cpp):
// x, y and z in lanes 0 to 2, lane 3 padding. SSE4.1 is in every x86-64
// target Sinew builds (the x86-64-v2 baseline and up), so there is no lane
// by lane form. Like Float8, every operation rounds exactly as the scalar
// one does (no fused multiply-add).
#pragma once

#include <cstdint>

#include <smmintrin.h>

#include "runtime/math/types.h"

namespace sinew {

struct Mask4 {
  __m128 m;
  // All-ones or all-zero floats, one per lane (as IntervalBound keeps its
  // per-axis flags).
  static Mask4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  bool any() const { return _mm_movemask_ps(m) != 0; }
  friend Mask4 operator&(Mask4 a, Mask4 b) { return {_mm_and_ps(a.m, b.m)}; }
  friend Mask4 operator|(Mask4 a, Mask4 b) { return {_mm_or_ps(a.m, b.m)}; }
};

struct Float4 {
  __m128 v;
  Float4() = default;
  Float4(__m128 x) : v(x) {}  // NOLINT: implicit from the native type
  Float4(float x) : v(_mm_set1_ps(x)) {}  // NOLINT: implicit broadcast
  // (p.x, p.y, p.z, w).
  Float4(const Vec3& p, float w) : v(_mm_setr_ps(p.x, p.y, p.z, w)) {}
  static Float4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  void store(float* p) const { _mm_storeu_ps(p, v); }

  friend Float4 operator+(Float4 a, Float4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend Float4 operator-(Float4 a, Float4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend Float4 operator*(Float4 a, Float4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend Mask4 operator<(Float4 a, Float4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
  friend Mask4 operator>(Float4 a, Float4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
};

// a < b ? a : b and a > b ? a : b per lane (the second operand on NaN).
inline Float4 min(Float4 a, Float4 b) { return {_mm_min_ps(a.v, b.v)}; }
inline Float4 max(Float4 a, Float4 b) { return {_mm_max_ps(a.v, b.v)}; }
inline Float4 abs(Float4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }
// mask ? yes : no per lane.
inline Float4 select(Mask4 mask, Float4 yes, Float4 no) { return {_mm_blendv_ps(no.v, yes.v, mask.m)}; }
// Lanes where a or b is NaN.
inline Mask4 unordered(Float4 a, Float4 b) { return {_mm_cmpunord_ps(a.v, b.v)}; }
// The largest and the smallest lane (no NaN lanes expected).
inline float reduce_max(Float4 a) {
  __m128 m = _mm_max_ps(a.v, _mm_movehl_ps(a.v, a.v));
  m = _mm_max_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}
inline float reduce_min(Float4 a) {
  __m128 m = _mm_min_ps(a.v, _mm_movehl_ps(a.v, a.v));
  m = _mm_min_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}

}  // namespace sinew
