// The fast (Moller-Trumbore) triangle test for eight rays against one
// triangle at once, AVX2. Per lane it evaluates exactly the expressions of
// intersect_triangle_fast (triangle_intersect.h) in the same order, and the
// build disables FMA contraction, so every lane's hit, t, u and v are
// bit-identical to the scalar test's: packets and single rays agree.
#pragma once

#include "runtime/math/simd.h"

#if SINEW_AVX2

#include <cstdint>

#include "raytrace/geometry/triangle_intersect.h"

namespace sinew::rt {

// The rays, structure of arrays, 32-byte aligned: origin o[axis][lane],
// direction d[axis][lane], and per lane t_min and the exclusive t_max.
struct RayLanes8 {
  const float (*o)[8];
  const float (*d)[8];
  const float* t_min;
  const float* t_max;
};

namespace detail {
// The last checks of both eight-lane tests (t_min <= t < t_max, finite t):
// the hit lanes of `lanes`, their t, u, v stored when there are any.
inline std::uint32_t accept_hits8(const RayLanes8& r, std::uint32_t lanes, __m256 ok, __m256 t, __m256 u, __m256 v,
                                  float* t_out, float* u_out, float* v_out) {
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_load_ps(r.t_min), _CMP_GE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_load_ps(r.t_max), _CMP_LT_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, _mm256_set1_ps(kFloatMax), _CMP_LE_OQ));
  const std::uint32_t hit = static_cast<std::uint32_t>(_mm256_movemask_ps(ok)) & lanes;
  if (hit != 0) {
    _mm256_storeu_ps(t_out, t);
    _mm256_storeu_ps(u_out, u);
    _mm256_storeu_ps(v_out, v);
  }
  return hit;
}
}  // namespace detail

// Returns the lanes of `lanes` that hit (t_min <= t < t_max, finite t, u, v),
// with their t, u, v in the out arrays (other lanes' entries are garbage).
// Zero-area triangles are the caller's check (detail::zero_area), once per
// triangle, as the scalar test does on its hit path.
inline std::uint32_t intersect_triangle_fast8(const RayLanes8& r, std::uint32_t lanes, const Vec3& p0,
                                              const Vec3& p1, const Vec3& p2, float* t_out, float* u_out,
                                              float* v_out) {
  const Vec3 e1s = p1 - p0;
  const Vec3 e2s = p2 - p0;
  const __m256 e1x = _mm256_set1_ps(e1s.x), e1y = _mm256_set1_ps(e1s.y), e1z = _mm256_set1_ps(e1s.z);
  const __m256 e2x = _mm256_set1_ps(e2s.x), e2y = _mm256_set1_ps(e2s.y), e2z = _mm256_set1_ps(e2s.z);
  const __m256 dx = _mm256_load_ps(r.d[0]), dy = _mm256_load_ps(r.d[1]), dz = _mm256_load_ps(r.d[2]);
  const auto mul = [](__m256 a, __m256 b) { return _mm256_mul_ps(a, b); };
  const auto add = [](__m256 a, __m256 b) { return _mm256_add_ps(a, b); };
  const auto sub = [](__m256 a, __m256 b) { return _mm256_sub_ps(a, b); };

  const __m256 px = sub(mul(dy, e2z), mul(dz, e2y));
  const __m256 py = sub(mul(dz, e2x), mul(dx, e2z));
  const __m256 pz = sub(mul(dx, e2y), mul(dy, e2x));
  const __m256 det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
  // finite_nonzero(det): 0 < |det| <= FLT_MAX, NaN excluded.
  const __m256 abs_det = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), det);
  __m256 ok = _mm256_and_ps(_mm256_cmp_ps(abs_det, _mm256_setzero_ps(), _CMP_GT_OQ),
                            _mm256_cmp_ps(abs_det, _mm256_set1_ps(detail::kFloatMax), _CMP_LE_OQ));
  // |det| > kFastDetTolerance * det_bound, as the scalar test computes it.
  const __m256 sign = _mm256_set1_ps(-0.0f);
  const auto abs = [&sign](__m256 a) { return _mm256_andnot_ps(sign, a); };
  const __m256 det_bound =
      add(add(mul(abs(e1x), add(abs(mul(dy, e2z)), abs(mul(dz, e2y)))),
              mul(abs(e1y), add(abs(mul(dz, e2x)), abs(mul(dx, e2z))))),
          mul(abs(e1z), add(abs(mul(dx, e2y)), abs(mul(dy, e2x)))));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(abs_det, mul(_mm256_set1_ps(detail::kFastDetTolerance), det_bound),
                                       _CMP_GT_OQ));
  if (_mm256_testz_ps(ok, ok) != 0) return 0;
  const __m256 inv_det = _mm256_div_ps(_mm256_set1_ps(1.0f), det);

  const __m256 tx = sub(_mm256_load_ps(r.o[0]), _mm256_set1_ps(p0.x));
  const __m256 ty = sub(_mm256_load_ps(r.o[1]), _mm256_set1_ps(p0.y));
  const __m256 tz = sub(_mm256_load_ps(r.o[2]), _mm256_set1_ps(p0.z));
  const __m256 u = mul(add(add(mul(tx, px), mul(ty, py)), mul(tz, pz)), inv_det);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 one = _mm256_set1_ps(1.0f);
  ok = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(u, zero, _CMP_GE_OQ), _mm256_cmp_ps(u, one, _CMP_LE_OQ)));
  if (_mm256_testz_ps(ok, ok) != 0) return 0;

  const __m256 qx = sub(mul(ty, e1z), mul(tz, e1y));
  const __m256 qy = sub(mul(tz, e1x), mul(tx, e1z));
  const __m256 qz = sub(mul(tx, e1y), mul(ty, e1x));
  const __m256 v = mul(add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz)), inv_det);
  ok = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_GE_OQ),
                                       _mm256_cmp_ps(add(u, v), one, _CMP_LE_OQ)));
  if (_mm256_testz_ps(ok, ok) != 0) return 0;

  const __m256 t = mul(add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz)), inv_det);
  return detail::accept_hits8(r, lanes, ok, t, u, v, t_out, u_out, v_out);
}

// A triangle's terms that depend only on the ray origin: for rays from one
// point (a camera's, in a large packet) they are computed once per
// triangle, not once per eight rays. Same expressions as the scalar test.
struct CommonOriginTriangle {
  Vec3 e1, e2;
  Vec3 tv;          // origin - p0
  Vec3 q;           // tv x e1
  float t_numerator = 0.0f;  // e2 . q
};

inline CommonOriginTriangle prepare_common_origin(const Vec3& origin, const Vec3& p0, const Vec3& p1,
                                                  const Vec3& p2) {
  CommonOriginTriangle c;
  c.e1 = p1 - p0;
  c.e2 = p2 - p0;
  c.tv = origin - p0;
  c.q = Vec3(c.tv.y * c.e1.z - c.tv.z * c.e1.y, c.tv.z * c.e1.x - c.tv.x * c.e1.z,
             c.tv.x * c.e1.y - c.tv.y * c.e1.x);
  c.t_numerator = (c.e2.x * c.q.x + c.e2.y * c.q.y) + c.e2.z * c.q.z;
  return c;
}

// prepare_common_origin for eight triangles at once, corner k's coordinate
// a of triangle i in p[k][a][i]: lane i of each array holds what
// prepare_common_origin gives triangle i, bit for bit (the same operations
// lane-wise; the build contracts no products into FMAs).
struct CommonOriginLanes8 {
  alignas(32) float e1[3][8], e2[3][8], tv[3][8], q[3][8], t_numerator[8];
  CommonOriginTriangle at(int i) const {
    CommonOriginTriangle c;
    c.e1 = Vec3(e1[0][i], e1[1][i], e1[2][i]);
    c.e2 = Vec3(e2[0][i], e2[1][i], e2[2][i]);
    c.tv = Vec3(tv[0][i], tv[1][i], tv[2][i]);
    c.q = Vec3(q[0][i], q[1][i], q[2][i]);
    c.t_numerator = t_numerator[i];
    return c;
  }
};

inline void prepare_common_origin8(const Vec3& origin, const float (&p)[3][3][8], CommonOriginLanes8& out) {
  const auto mul = [](__m256 a, __m256 b) { return _mm256_mul_ps(a, b); };
  const auto add = [](__m256 a, __m256 b) { return _mm256_add_ps(a, b); };
  const auto sub = [](__m256 a, __m256 b) { return _mm256_sub_ps(a, b); };
  const float o[3] = {origin.x, origin.y, origin.z};
  __m256 e1[3], e2[3], tv[3];
  for (int a = 0; a < 3; ++a) {
    const __m256 p0 = _mm256_load_ps(p[0][a]);
    e1[a] = sub(_mm256_load_ps(p[1][a]), p0);
    e2[a] = sub(_mm256_load_ps(p[2][a]), p0);
    tv[a] = sub(_mm256_set1_ps(o[a]), p0);
    _mm256_store_ps(out.e1[a], e1[a]);
    _mm256_store_ps(out.e2[a], e2[a]);
    _mm256_store_ps(out.tv[a], tv[a]);
  }
  const __m256 q[3] = {sub(mul(tv[1], e1[2]), mul(tv[2], e1[1])), sub(mul(tv[2], e1[0]), mul(tv[0], e1[2])),
                       sub(mul(tv[0], e1[1]), mul(tv[1], e1[0]))};
  for (int a = 0; a < 3; ++a) _mm256_store_ps(out.q[a], q[a]);
  _mm256_store_ps(out.t_numerator, add(add(mul(e2[0], q[0]), mul(e2[1], q[1])), mul(e2[2], q[2])));
}

// intersect_triangle_fast8 for rays that all start at the origin `c` was
// prepared with (r.o is not read): per lane the same values, bit for bit.
inline std::uint32_t intersect_triangle_fast8_common_origin(const RayLanes8& r, std::uint32_t lanes,
                                                            const CommonOriginTriangle& c, float* t_out,
                                                            float* u_out, float* v_out) {
  const __m256 e1x = _mm256_set1_ps(c.e1.x), e1y = _mm256_set1_ps(c.e1.y), e1z = _mm256_set1_ps(c.e1.z);
  const __m256 e2x = _mm256_set1_ps(c.e2.x), e2y = _mm256_set1_ps(c.e2.y), e2z = _mm256_set1_ps(c.e2.z);
  const __m256 dx = _mm256_load_ps(r.d[0]), dy = _mm256_load_ps(r.d[1]), dz = _mm256_load_ps(r.d[2]);
  const auto mul = [](__m256 a, __m256 b) { return _mm256_mul_ps(a, b); };
  const auto add = [](__m256 a, __m256 b) { return _mm256_add_ps(a, b); };
  const auto sub = [](__m256 a, __m256 b) { return _mm256_sub_ps(a, b); };
  const __m256 sign = _mm256_set1_ps(-0.0f);
  const auto abs = [&sign](__m256 a) { return _mm256_andnot_ps(sign, a); };

  const __m256 dy_e2z = mul(dy, e2z), dz_e2y = mul(dz, e2y);
  const __m256 dz_e2x = mul(dz, e2x), dx_e2z = mul(dx, e2z);
  const __m256 dx_e2y = mul(dx, e2y), dy_e2x = mul(dy, e2x);
  const __m256 px = sub(dy_e2z, dz_e2y);
  const __m256 py = sub(dz_e2x, dx_e2z);
  const __m256 pz = sub(dx_e2y, dy_e2x);
  const __m256 det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
  const __m256 abs_det = abs(det);
  __m256 ok = _mm256_and_ps(_mm256_cmp_ps(abs_det, _mm256_setzero_ps(), _CMP_GT_OQ),
                            _mm256_cmp_ps(abs_det, _mm256_set1_ps(detail::kFloatMax), _CMP_LE_OQ));
  const __m256 det_bound = add(add(mul(abs(e1x), add(abs(dy_e2z), abs(dz_e2y))),
                                   mul(abs(e1y), add(abs(dz_e2x), abs(dx_e2z)))),
                               mul(abs(e1z), add(abs(dx_e2y), abs(dy_e2x))));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(abs_det, mul(_mm256_set1_ps(detail::kFastDetTolerance), det_bound),
                                       _CMP_GT_OQ));
  if (_mm256_testz_ps(ok, ok) != 0) return 0;
  const __m256 inv_det = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
  const __m256 u = mul(add(add(mul(_mm256_set1_ps(c.tv.x), px), mul(_mm256_set1_ps(c.tv.y), py)),
                           mul(_mm256_set1_ps(c.tv.z), pz)),
                       inv_det);
  const __m256 v = mul(add(add(mul(dx, _mm256_set1_ps(c.q.x)), mul(dy, _mm256_set1_ps(c.q.y))),
                           mul(dz, _mm256_set1_ps(c.q.z))),
                       inv_det);
  const __m256 t = mul(_mm256_set1_ps(c.t_numerator), inv_det);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 one = _mm256_set1_ps(1.0f);
  ok = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(u, zero, _CMP_GE_OQ), _mm256_cmp_ps(u, one, _CMP_LE_OQ)));
  ok = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_GE_OQ),
                                       _mm256_cmp_ps(add(u, v), one, _CMP_LE_OQ)));
  return detail::accept_hits8(r, lanes, ok, t, u, v, t_out, u_out, v_out);
}

}  // namespace sinew::rt

#endif  // SINEW_AVX2
