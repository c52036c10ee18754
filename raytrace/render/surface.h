// The surface at a hit and the shadow rays that leave it: the scalar
// reference the tile stages (render/stages/) compute eight lanes at a time.
#pragma once

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "runtime/math/ray.h"
#include "runtime/math/types.h"

namespace sinew::rt {

// The shading inputs at a hit, in world space.
struct SurfacePoint {
  Vec3 position{0.0f};
  Vec3 geometric_normal{0.0f};  // unit
  Vec3 shading_normal{0.0f};    // unit; the geometric normal where no vertex normals exist
  Vec3 albedo{0.0f};
  Vec3 error{0.0f};  // per axis, a bound on the rounding of `position` and of a triangle test started there
};
SurfacePoint surface_at(const Scene& scene, const Hit& hit, const Vec3& default_albedo);

// A directional light's shadow ray origin: `p` pushed off the surface along
// the geometric normal, to the side `toward` points to, by its rounding
// error bound (pbrt-v4's OffsetRayOrigin idea), so neither acne far from
// the origin nor a visible gap at tiny scales.
Vec3 offset_origin(const SurfacePoint& surface, const Vec3& toward);

// A point light's shadow ray: from the light to the surface point pushed
// off toward `toward` (offset_origin), t in [0, 1). Traced from the light,
// a tile's shadow rays share one origin, as its camera rays do
// (docs/RAYTRACE.md, "Shadow rays"). The push covers the point's rounding
// and also a triangle test's along a ray from the light, which grows with
// the light's magnitude and distance: gamma(32) (|light| + 2 |light - p|)
// more per axis, so the ray stops short of the surface it ends on (an
// eighth of it was not enough in tests/raytrace/render_extremes_test.cpp).
Ray shadow_ray_from_light(const SurfacePoint& surface, const Vec3& toward, const Vec3& light);

}  // namespace sinew::rt
