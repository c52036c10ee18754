// The fast (Moller-Trumbore) triangle test for eight rays against one
// triangle at once, over Float8 (runtime/math/float8.h). Per lane it
// evaluates exactly the expressions of intersect_triangle_fast
// (triangle_intersect.h) in the same order, and the build disables FMA
// contraction, so every lane's hit, t, u and v are bit-identical to the
// scalar test's: packets and single rays agree.
#pragma once

#include <cstdint>

#include "raytrace/geometry/triangle_intersect.h"
#include "runtime/math/float8.h"

namespace sinew::rt {

// The rays, structure of arrays: origin o[axis][lane], direction
// d[axis][lane], and per lane t_min and the exclusive t_max.
struct RayLanes8 {
  const float (*o)[8];
  const float (*d)[8];
  const float* t_min;
  const float* t_max;
};

namespace detail {
// The last checks of both eight-lane tests (t_min <= t < t_max, finite t):
// the hit lanes of `lanes`, their t, u, v stored when there are any.
inline std::uint32_t accept_hits8(const RayLanes8& r, std::uint32_t lanes, Mask8 ok, Float8 t, Float8 u, Float8 v,
                                  float* t_out, float* u_out, float* v_out) {
  ok = ok & (t >= Float8::load(r.t_min)) & (t < Float8::load(r.t_max)) & (t <= Float8(kFloatMax));
  const std::uint32_t hit = ok.bits() & lanes;
  if (hit != 0) {
    t.store(t_out);
    u.store(u_out);
    v.store(v_out);
  }
  return hit;
}

// The scalar test's determinant checks, lane-wise: finite_nonzero(det)
// (0 < |det| <= FLT_MAX, NaN excluded) and |det| > kFastDetTolerance *
// det_bound.
inline Mask8 usable_det8(Float8 det, Float8 det_bound) {
  const Float8 abs_det = abs(det);
  return (abs_det > Float8(0.0f)) & (abs_det <= Float8(kFloatMax)) &
         (abs_det > Float8(kFastDetTolerance) * det_bound);
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
  const Float8 e1x(e1s.x), e1y(e1s.y), e1z(e1s.z);
  const Float8 e2x(e2s.x), e2y(e2s.y), e2z(e2s.z);
  const Float8 dx = Float8::load(r.d[0]), dy = Float8::load(r.d[1]), dz = Float8::load(r.d[2]);

  const Float8 px = dy * e2z - dz * e2y;
  const Float8 py = dz * e2x - dx * e2z;
  const Float8 pz = dx * e2y - dy * e2x;
  const Float8 det = (e1x * px + e1y * py) + e1z * pz;
  const Float8 det_bound = (abs(e1x) * (abs(dy * e2z) + abs(dz * e2y)) + abs(e1y) * (abs(dz * e2x) + abs(dx * e2z))) +
                           abs(e1z) * (abs(dx * e2y) + abs(dy * e2x));
  Mask8 ok = detail::usable_det8(det, det_bound);
  if (!ok.any()) return 0;
  const Float8 inv_det = Float8(1.0f) / det;

  const Float8 tx = Float8::load(r.o[0]) - Float8(p0.x);
  const Float8 ty = Float8::load(r.o[1]) - Float8(p0.y);
  const Float8 tz = Float8::load(r.o[2]) - Float8(p0.z);
  const Float8 u = ((tx * px + ty * py) + tz * pz) * inv_det;
  const Float8 zero(0.0f), one(1.0f);
  ok = ok & (u >= zero) & (u <= one);
  if (!ok.any()) return 0;

  const Float8 qx = ty * e1z - tz * e1y;
  const Float8 qy = tz * e1x - tx * e1z;
  const Float8 qz = tx * e1y - ty * e1x;
  const Float8 v = ((dx * qx + dy * qy) + dz * qz) * inv_det;
  ok = ok & (v >= zero) & (u + v <= one);
  if (!ok.any()) return 0;

  const Float8 t = ((e2x * qx + e2y * qy) + e2z * qz) * inv_det;
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
  const float o[3] = {origin.x, origin.y, origin.z};
  Float8 e1[3], e2[3], tv[3];
  for (int a = 0; a < 3; ++a) {
    const Float8 p0 = Float8::load(p[0][a]);
    e1[a] = Float8::load(p[1][a]) - p0;
    e2[a] = Float8::load(p[2][a]) - p0;
    tv[a] = Float8(o[a]) - p0;
    e1[a].store(out.e1[a]);
    e2[a].store(out.e2[a]);
    tv[a].store(out.tv[a]);
  }
  const Float8 q[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0]};
  for (int a = 0; a < 3; ++a) q[a].store(out.q[a]);
  ((e2[0] * q[0] + e2[1] * q[1]) + e2[2] * q[2]).store(out.t_numerator);
}

// intersect_triangle_fast8 for rays that all start at the origin `c` was
// prepared with (r.o is not read): per lane the same values, bit for bit.
inline std::uint32_t intersect_triangle_fast8_common_origin(const RayLanes8& r, std::uint32_t lanes,
                                                            const CommonOriginTriangle& c, float* t_out,
                                                            float* u_out, float* v_out) {
  const Float8 e1x(c.e1.x), e1y(c.e1.y), e1z(c.e1.z);
  const Float8 e2x(c.e2.x), e2y(c.e2.y), e2z(c.e2.z);
  const Float8 dx = Float8::load(r.d[0]), dy = Float8::load(r.d[1]), dz = Float8::load(r.d[2]);

  const Float8 dy_e2z = dy * e2z, dz_e2y = dz * e2y;
  const Float8 dz_e2x = dz * e2x, dx_e2z = dx * e2z;
  const Float8 dx_e2y = dx * e2y, dy_e2x = dy * e2x;
  const Float8 px = dy_e2z - dz_e2y;
  const Float8 py = dz_e2x - dx_e2z;
  const Float8 pz = dx_e2y - dy_e2x;
  const Float8 det = (e1x * px + e1y * py) + e1z * pz;
  const Float8 det_bound = (abs(e1x) * (abs(dy_e2z) + abs(dz_e2y)) + abs(e1y) * (abs(dz_e2x) + abs(dx_e2z))) +
                           abs(e1z) * (abs(dx_e2y) + abs(dy_e2x));
  Mask8 ok = detail::usable_det8(det, det_bound);
  if (!ok.any()) return 0;
  const Float8 inv_det = Float8(1.0f) / det;
  const Float8 u = ((Float8(c.tv.x) * px + Float8(c.tv.y) * py) + Float8(c.tv.z) * pz) * inv_det;
  const Float8 v = ((dx * Float8(c.q.x) + dy * Float8(c.q.y)) + dz * Float8(c.q.z)) * inv_det;
  const Float8 t = Float8(c.t_numerator) * inv_det;
  const Float8 zero(0.0f), one(1.0f);
  ok = ok & (u >= zero) & (u <= one) & (v >= zero) & (u + v <= one);
  return detail::accept_hits8(r, lanes, ok, t, u, v, t_out, u_out, v_out);
}

}  // namespace sinew::rt
