// Ray-triangle tests against skinned (world-space, per-frame) triangles.
//
// Two tests, selectable per render (docs/DESIGN.md section 5):
//  - kFast: Moller-Trumbore. Skinned triangles move every frame, so tests
//    that need per-triangle precomputation (Wald 2004's projection test)
//    would pay it every frame; Moller-Trumbore needs none.
//  - kWatertight: Woop, Benthin and Wald 2013: the ray is sheared so it runs
//    along +z through the origin, and the signs of the 2D edge functions
//    are exact (the paper's double-precision fallback, here always taken: see
//    below), so a ray never passes between two triangles sharing an edge.
//
// Both report t along the ray as given (the direction is not normalised) and
// barycentrics (u, v) of the second and third vertex.
//
// The two tests are defined inline here because they run in the innermost
// loop of traversal; prepare_watertight (once per ray) lives in the .cpp.
// The fast test spells out every product and sum in a fixed order: its
// 8-wide twin (triangle_intersect8.h) evaluates the same expressions lane
// by lane, and the build turns FMA contraction off
// (cmake/SinewCompilerOptions.cmake), so a packet lane and a single ray get
// bit-identical results. The watertight test computes its shear and edge
// products in double, where a product of two floats is exact: its exact
// antisymmetry then holds even where a compiler does contract.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "runtime/math/ray.h"
#include "runtime/math/types.h"

namespace sinew::rt {

enum class TriangleTest : std::uint8_t { kFast, kWatertight };

// Per-ray data for the watertight test, computed once per ray (and once per
// bone-space transform is NOT needed: triangles stay in world space).
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;  // kz: the axis of the largest |direction|
  float sx = 0.0f, sy = 0.0f, sz = 1.0f;
  Vec3 origin{0.0f};
};
WatertightRay prepare_watertight(const Ray& ray);

struct TriangleHit {
  float t;
  float u;
  float v;
};

// Each returns true and fills `hit` when the ray hits the triangle at
// t_min <= t < t_max (t_max exclusive, so a nearer-hit search can pass the
// best t so far and ties keep the first triangle found). Degenerate
// (zero-area: exactly parallel edges in float, e.g. repeated or collinear
// vertices) triangles never report a hit. Back faces are hit too.
// A reported hit always has finite t, u, v; NaN or infinite input never hits.
inline bool intersect_triangle_fast(const Ray& ray, float t_max, const Vec3& p0, const Vec3& p1,
                                    const Vec3& p2, TriangleHit& hit);
inline bool intersect_triangle_watertight(const WatertightRay& wr, const Ray& ray, float t_max,
                                          const Vec3& p0, const Vec3& p1, const Vec3& p2, TriangleHit& hit);

namespace detail {
inline constexpr float kFloatMax = std::numeric_limits<float>::max();
// The fast test's determinant is a sum of products whose rounding error is
// below a few float epsilons times the same sum taken over absolute values
// (fast_det_bound). A |det| under this fraction of that bound has no
// reliable sign or size: the ray lies in the triangle's plane up to
// rounding, e.g. a ray along one of its edges, where u, v and t come out as
// ratios of rounding noise (a "hit" at t = 0 metres away from the triangle).
// Such rays are reported as misses; the watertight test handles them exactly.
inline constexpr float kFastDetTolerance = 8.0f * std::numeric_limits<float>::epsilon();

// True for finite non-zero x; false for zero, infinities and NaN.
inline bool finite_nonzero(float x) { return (x > 0.0f && x <= kFloatMax) || (x < 0.0f && x >= -kFloatMax); }

// x - s * z for one sheared vertex coordinate. The product is exact in
// double, so the result is the same whether or not the compiler fuses it
// into an FMA: a vertex shared by several triangles shears identically in
// each of them.
inline float shear(float x, float s, float z) {
  return static_cast<float>(static_cast<double>(x) - static_cast<double>(s) * static_cast<double>(z));
}

// a*b - c*d with both products exact in double: one rounding, independent of
// FMA contraction, and cross2(a,b,c,d) == -cross2(c,d,a,b) exactly.
inline double cross2(float a, float b, float c, float d) {
  return static_cast<double>(a) * static_cast<double>(b) - static_cast<double>(c) * static_cast<double>(d);
}

struct ShearedVertex {
  float x, y, z;
};

// A vertex in the ray's frame: translated to the ray origin, axes permuted
// so z is the ray's dominant axis, sheared so the ray runs along +z (x, y),
// z scaled so the ray reaches the vertex's depth at t = z.
inline ShearedVertex shear_vertex(const Vec3& p, const WatertightRay& wr) {
  const Vec3 rel = p - wr.origin;
  // An array, not glm's operator[] (a switch on the index), for the permute.
  const float coords[3] = {rel.x, rel.y, rel.z};
  const float z = coords[wr.kz];
  return {shear(coords[wr.kx], wr.sx, z), shear(coords[wr.ky], wr.sy, z), wr.sz * z};
}

// Whether the edges are exactly parallel (repeated or collinear vertices).
// Rounding can leave such a triangle a sliver of non-zero area in the ray's
// frame, so both tests check this too, on the rare hit path only.
inline bool zero_area(const Vec3& e1, const Vec3& e2) {
  return cross2(e1.y, e2.z, e1.z, e2.y) == 0.0 && cross2(e1.z, e2.x, e1.x, e2.z) == 0.0 &&
         cross2(e1.x, e2.y, e1.y, e2.x) == 0.0;
}
}  // namespace detail

inline bool intersect_triangle_fast(const Ray& ray, float t_max, const Vec3& p0, const Vec3& p1,
                                    const Vec3& p2, TriangleHit& hit) {
  const Vec3 e1 = p1 - p0;
  const Vec3 e2 = p2 - p0;
  const Vec3& d = ray.direction;
  // pvec = d x e2; det = e1 . pvec (written out: see the header comment).
  const float px = d.y * e2.z - d.z * e2.y;
  const float py = d.z * e2.x - d.x * e2.z;
  const float pz = d.x * e2.y - d.y * e2.x;
  const float det = (e1.x * px + e1.y * py) + e1.z * pz;
  // Exactly zero: parallel ray or zero-area triangle. Non-finite: an
  // infinite or NaN coordinate always makes det inf or NaN, so this one test
  // keeps such triangles from producing garbage hits.
  if (!detail::finite_nonzero(det)) return false;
  // Within rounding of zero: the ray lies in the triangle's plane
  // (kFastDetTolerance). Same expression, same order as the 8-wide twin.
  const float det_bound =
      (std::fabs(e1.x) * (std::fabs(d.y * e2.z) + std::fabs(d.z * e2.y)) +
       std::fabs(e1.y) * (std::fabs(d.z * e2.x) + std::fabs(d.x * e2.z))) +
      std::fabs(e1.z) * (std::fabs(d.x * e2.y) + std::fabs(d.y * e2.x));
  if (!(std::fabs(det) > detail::kFastDetTolerance * det_bound)) return false;
  const float inv_det = 1.0f / det;

  const Vec3 tv = ray.origin - p0;
  const float u = ((tv.x * px + tv.y * py) + tv.z * pz) * inv_det;
  // Written so that NaN fails every comparison and misses.
  if (!(u >= 0.0f && u <= 1.0f)) return false;

  // qvec = tvec x e1
  const float qx = tv.y * e1.z - tv.z * e1.y;
  const float qy = tv.z * e1.x - tv.x * e1.z;
  const float qz = tv.x * e1.y - tv.y * e1.x;
  const float v = ((d.x * qx + d.y * qy) + d.z * qz) * inv_det;
  if (!(v >= 0.0f && u + v <= 1.0f)) return false;

  const float t = ((e2.x * qx + e2.y * qy) + e2.z * qz) * inv_det;
  if (!(t >= ray.t_min && t < t_max && t <= detail::kFloatMax)) return false;
  if (detail::zero_area(e1, e2)) return false;
  hit = {t, u, v};
  return true;
}

inline bool intersect_triangle_watertight(const WatertightRay& wr, const Ray& ray, float t_max,
                                          const Vec3& p0, const Vec3& p1, const Vec3& p2, TriangleHit& hit) {
  // Vertices relative to the ray origin, sheared so the ray runs along +z.
  const detail::ShearedVertex a = detail::shear_vertex(p0, wr);
  const detail::ShearedVertex b = detail::shear_vertex(p1, wr);
  const detail::ShearedVertex c = detail::shear_vertex(p2, wr);

  // 2D edge functions: uu is the weight of p0 (edge p1-p2), vv of p1, ww of p2.
  // Products of floats are exact in double, so each sign is exact (the
  // paper's double fallback, taken always) and a shared edge gives exactly
  // the negated value in the neighbouring triangle, FMA or not.
  const double uu = detail::cross2(c.x, b.y, c.y, b.x);
  const double vv = detail::cross2(a.x, c.y, a.y, c.x);
  const double ww = detail::cross2(b.x, a.y, b.y, a.x);
  // Inside when all three share a sign (either winding: back faces hit);
  // NaN fails both tests.
  const bool all_nonneg = uu >= 0.0 && vv >= 0.0 && ww >= 0.0;
  const bool all_nonpos = uu <= 0.0 && vv <= 0.0 && ww <= 0.0;
  if (!all_nonneg && !all_nonpos) return false;
  const double det = uu + vv + ww;
  // Zero: the ray grazes the triangle's plane or the triangle has no area in
  // the ray's projection. Non-finite: an infinite coordinate.
  if (!(det != 0.0 && std::isfinite(det))) return false;

  // Scaled hit distance, range-tested before the division.
  const double scaled_t =
      uu * static_cast<double>(a.z) + vv * static_cast<double>(b.z) + ww * static_cast<double>(c.z);
  const double abs_det = det < 0.0 ? -det : det;
  const double abs_scaled_t = det < 0.0 ? -scaled_t : scaled_t;
  if (!(abs_scaled_t >= abs_det * static_cast<double>(ray.t_min) &&
        abs_scaled_t < abs_det * static_cast<double>(t_max))) {
    return false;
  }

  const double inv_det = 1.0 / det;
  const float t = static_cast<float>(scaled_t * inv_det);
  // Re-checked after rounding so the reported t honours the contract exactly.
  if (!(t >= ray.t_min && t < t_max && t <= detail::kFloatMax)) return false;
  if (detail::zero_area(p1 - p0, p2 - p0)) return false;
  hit = {t, static_cast<float>(vv * inv_det), static_cast<float>(ww * inv_det)};
  return true;
}

}  // namespace sinew::rt
