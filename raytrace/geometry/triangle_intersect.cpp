#include "raytrace/geometry/triangle_intersect.h"

#include <cmath>
#include <utility>

namespace sinew::rt {

WatertightRay prepare_watertight(const Ray& ray) {
  WatertightRay wr;
  const Vec3& d = ray.direction;
  const Vec3 abs_d = glm::abs(d);
  // The dominant axis becomes z, so the shear factors below stay in [-1, 1].
  wr.kz = 2;
  if (abs_d.x > abs_d.y && abs_d.x > abs_d.z) {
    wr.kz = 0;
  } else if (abs_d.y > abs_d.z) {
    wr.kz = 1;
  }
  wr.kx = (wr.kz + 1) % 3;
  wr.ky = (wr.kx + 1) % 3;
  // Swapping x and y for a negative z keeps the projected winding, so the
  // sign of det still tells front from back face (and u, v their vertices).
  if (d[wr.kz] < 0.0f) std::swap(wr.kx, wr.ky);
  wr.sx = d[wr.kx] / d[wr.kz];
  wr.sy = d[wr.ky] / d[wr.kz];
  wr.sz = 1.0f / d[wr.kz];
  wr.origin = ray.origin;
  return wr;
}

}  // namespace sinew::rt
