// One ray's nearest hit from a contender against the brute-force
// reference's, with the tolerances every peer benchmark uses (the camera
// rays of BruteForceGate and the random rays of `sinew-bench queries`).
//
// Tolerances: t relative 1e-4. A different triangle at the same t passes
// when the ray really hits it there (a shared edge or vertex). A hit
// against a miss, or a nearer hit on one side only, passes when the nearer
// triangle is only grazed: the ray passes near its edge (its smallest
// barycentric, in double precision, within graze_tolerance of 0) or meets
// it edge-on (within 1e-3 radians of its plane, where a rounding in a
// corner moves the hit along the ray a thousand times as far). Two float
// triangle tests may decide such a ray either way. Such grazes are their
// own verdict, so callers can count them.
//
// The triangles' corners come from the caller: `corners_of(instance,
// triangle)` returns std::optional<std::array<Vec3, 3>> (empty for an id it
// does not know), so each caller keeps its triangles however it likes.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "runtime/math/ray.h"
#include "runtime/math/types.h"

namespace sinew::bench {

enum class HitVerdict { kSame, kGraze, kDifferent };

inline constexpr double kHitTolerance = 1e-4;        // relative, on t
inline constexpr double kGrazeBarycentric = 1e-5;   // how close to an edge a graze is, at least
inline constexpr double kEdgeOnSine = 1e-3;         // how close to its plane a ray meets an edge-on triangle

// The ray against one triangle in double precision: its t and its smallest
// barycentric (negative: outside). False for a ray parallel to its plane.
inline bool exact_triangle_hit(const std::array<Vec3, 3>& corners, const Ray& ray, double& t, double& min_bary) {
  using D3 = std::array<double, 3>;
  const auto d = [](const Vec3& v) { return D3{v.x, v.y, v.z}; };
  const auto sub = [](const D3& a, const D3& b) { return D3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const auto cross = [](const D3& a, const D3& b) {
    return D3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const auto dot = [](const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const D3 p0 = d(corners[0]), e1 = sub(d(corners[1]), p0), e2 = sub(d(corners[2]), p0);
  const D3 dir = d(ray.direction);
  const D3 pv = cross(dir, e2);
  const double det = dot(e1, pv);
  if (det == 0.0) return false;
  const D3 tv = sub(d(ray.origin), p0);
  const double u = dot(tv, pv) / det;
  const D3 qv = cross(tv, e1);
  const double v = dot(dir, qv) / det;
  t = dot(e2, qv) / det;
  min_bary = std::min({u, v, 1.0 - u - v});
  return true;
}

// The sine of the angle between the ray and the triangle's plane (0: the
// ray runs in the plane), in double precision; 0 for a degenerate triangle.
inline double ray_plane_sine(const std::array<Vec3, 3>& corners, const Ray& ray) {
  const glm::dvec3 p0(corners[0]);
  const glm::dvec3 n = glm::cross(glm::dvec3(corners[1]) - p0, glm::dvec3(corners[2]) - p0);
  const glm::dvec3 d(ray.direction);
  const double scale = glm::length(n) * glm::length(d);
  return scale > 0.0 ? std::fabs(glm::dot(n, d)) / scale : 0.0;
}

// How far from an edge, in barycentrics, a float triangle test may still
// decide either way: the rounding of coordinates as large as the corners'
// and the ray origin's (8 units in the last place of a float) over the
// triangle's smallest height; never below kGrazeBarycentric. Small
// triangles far from the origin (a crowd's far end) get more; a sliver,
// whose barycentrics hang on that rounding, gets it all.
inline double graze_tolerance(const std::array<Vec3, 3>& corners, const Ray& ray) {
  double magnitude = 0.0;
  for (const Vec3& p : {corners[0], corners[1], corners[2], ray.origin}) {
    magnitude = std::max({magnitude, std::fabs(static_cast<double>(p.x)), std::fabs(static_cast<double>(p.y)),
                          std::fabs(static_cast<double>(p.z))});
  }
  const double rounding = 8.0 * 0x1p-24 * magnitude;
  const glm::dvec3 p0(corners[0]), p1(corners[1]), p2(corners[2]);
  const double twice_area = glm::length(glm::cross(p1 - p0, p2 - p0));
  const double longest = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
  if (!(twice_area > 0.0)) return std::numeric_limits<double>::infinity();
  return std::max(kGrazeBarycentric, rounding / (twice_area / longest));
}

// `ours` against `ref` (the brute force's) for `ray`.
template <class CornersOf>
HitVerdict compare_nearest_hits(const Hit& ours, const Hit& ref, const Ray& ray, const CornersOf& corners_of) {
  const auto grazed = [&](const Hit& hit) {
    const std::optional<std::array<Vec3, 3>> corners = corners_of(hit.instance_id, hit.triangle_id);
    if (!corners) return false;
    if (ray_plane_sine(*corners, ray) < kEdgeOnSine) return true;  // edge-on
    double t = 0.0, min_bary = 0.0;
    return exact_triangle_hit(*corners, ray, t, min_bary) && std::fabs(min_bary) <= graze_tolerance(*corners, ray);
  };
  if (!ours.valid() && !ref.valid()) return HitVerdict::kSame;
  if (ours.valid() && ref.valid()) {
    const double tol = kHitTolerance * std::max(static_cast<double>(std::fabs(ref.t)), 1e-30);
    if (std::fabs(static_cast<double>(ours.t) - static_cast<double>(ref.t)) <= tol) {
      if (ours.triangle_id == ref.triangle_id && ours.instance_id == ref.instance_id) return HitVerdict::kSame;
      // Another triangle at the same t: does the ray really hit it there?
      const std::optional<std::array<Vec3, 3>> corners = corners_of(ours.instance_id, ours.triangle_id);
      double t = 0.0, min_bary = 0.0;
      const bool real = corners && exact_triangle_hit(*corners, ray, t, min_bary) &&
                        min_bary >= -graze_tolerance(*corners, ray) && std::fabs(t - static_cast<double>(ref.t)) <= tol;
      if (real) return HitVerdict::kSame;
      // The reference's own hit on an edge: the ray passes through the
      // edge, and the triangle across it at the same t is a tie that the
      // float test may settle either way (its barycentrics are those of
      // another triangle, so its distance past the edge is on another
      // scale). Or either triangle is edge-on, its t ill-conditioned.
      return grazed(ref) || grazed(ours) ? HitVerdict::kGraze : HitVerdict::kDifferent;
    }
    // Different depths: the nearer one must be a graze the other missed.
    const Hit& nearer = ours.t < ref.t ? ours : ref;
    return grazed(nearer) ? HitVerdict::kGraze : HitVerdict::kDifferent;
  }
  return grazed(ours.valid() ? ours : ref) ? HitVerdict::kGraze : HitVerdict::kDifferent;
}

}  // namespace sinew::bench
