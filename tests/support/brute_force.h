// The independent reference for every ray-tracing test: every triangle of
// a prepared scene (skinned instances and static meshes) in one flat list,
// intersected one by one, with no acceleration structure of Sinew's.
//
// For primary rays a ScreenBinner makes this affordable without giving up
// exactness: each triangle is projected into the image and listed in every
// tile its (conservatively grown) screen rectangle touches; a triangle that
// reaches behind the eye plane is listed everywhere. A pixel's ray can only
// hit triangles listed in its tile, so the nearest over that list is the
// nearest over all.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "runtime/math/ray.h"

namespace sinew::testing_support {

struct SoupTriangle {
  Vec3 p0, p1, p2;
  std::uint32_t triangle_id;
  std::uint32_t instance_id;
};

inline std::vector<SoupTriangle> world_triangles(const rt::Scene& scene) {
  std::vector<SoupTriangle> soup;
  for (const rt::InstanceFrame& frame : scene.instances()) {
    if (!frame.live) continue;
    const SkinnedMesh& mesh = *scene.characters()[frame.character].mesh;
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& v = mesh.triangles[t];
      soup.push_back({frame.positions[v[0]], frame.positions[v[1]], frame.positions[v[2]], t, frame.instance_id});
    }
  }
  for (const rt::Scene::StaticMesh& mesh : scene.static_meshes()) {
    if (!mesh.live) continue;
    for (std::uint32_t t = 0; t < mesh.desc.triangles.size(); ++t) {
      const auto& v = mesh.desc.triangles[t];
      soup.push_back({mesh.desc.positions[v[0]], mesh.desc.positions[v[1]], mesh.desc.positions[v[2]], t,
                      mesh.instance_id});
    }
  }
  return soup;
}

inline bool test_one(const SoupTriangle& tri, const Ray& ray, const rt::WatertightRay& wr,
                     rt::TriangleTest test, float t_max, rt::TriangleHit& hit) {
  if (test == rt::TriangleTest::kWatertight) {
    return rt::intersect_triangle_watertight(wr, ray, t_max, tri.p0, tri.p1, tri.p2, hit);
  }
  return rt::intersect_triangle_fast(ray, t_max, tri.p0, tri.p1, tri.p2, hit);
}

inline bool test_one(const SoupTriangle& tri, const Ray& ray, rt::TriangleTest test, float t_max,
                     rt::TriangleHit& hit) {
  return test_one(tri, ray, rt::prepare_watertight(ray), test, t_max, hit);
}

// Nearest hit over `candidates` (indices into soup) or, when empty and
// `all` is set, over the whole soup. Ties keep the first in soup order.
inline Hit nearest(std::span<const SoupTriangle> soup, const Ray& ray, rt::TriangleTest test) {
  Hit best;
  float t_max = ray.t_max;
  const rt::WatertightRay wr = rt::prepare_watertight(ray);
  for (const SoupTriangle& tri : soup) {
    rt::TriangleHit h;
    if (test_one(tri, ray, wr, test, t_max, h)) {
      t_max = h.t;
      best = Hit{h.t, h.u, h.v, tri.triangle_id, tri.instance_id};
    }
  }
  return best;
}

inline Hit nearest_of(std::span<const SoupTriangle> soup, std::span<const std::uint32_t> candidates,
                      const Ray& ray, rt::TriangleTest test, Hit best = {}) {
  float t_max = best.valid() ? best.t : ray.t_max;
  const rt::WatertightRay wr = rt::prepare_watertight(ray);
  for (const std::uint32_t i : candidates) {
    rt::TriangleHit h;
    if (test_one(soup[i], ray, wr, test, t_max, h)) {
      t_max = h.t;
      best = Hit{h.t, h.u, h.v, soup[i].triangle_id, soup[i].instance_id};
    }
  }
  return best;
}

inline bool any_hit(std::span<const SoupTriangle> soup, const Ray& ray, rt::TriangleTest test) {
  const rt::WatertightRay wr = rt::prepare_watertight(ray);
  for (const SoupTriangle& tri : soup) {
    rt::TriangleHit h;
    if (test_one(tri, ray, wr, test, ray.t_max, h)) return true;
  }
  return false;
}

class ScreenBinner {
 public:
  ScreenBinner(std::span<const SoupTriangle> soup, const rt::PinholeCamera& camera, int tile = 8)
      : tile_(tile), tiles_x_((camera.width() + tile - 1) / tile), tiles_y_((camera.height() + tile - 1) / tile),
        bins_(static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>(tiles_y_)) {
    // Image plane coordinates: a direction d maps to pixel
    // x = W (1 + a/(f tan aspect)) / 2, y = H (1 - b/(f tan)) / 2 with
    // (a, b, f) = d in the camera's (right, up, forward) frame.
    const Ray r00 = camera.ray_at(0.0f, 0.0f);
    const Ray r11 = camera.ray_at(static_cast<float>(camera.width()), static_cast<float>(camera.height()));
    const float f00 = glm::dot(r00.direction, camera.forward());
    const float f11 = glm::dot(r11.direction, camera.forward());
    const float sx = glm::dot(r00.direction, camera.right()) / f00;  // image-plane x at pixel x = 0
    const float sx1 = glm::dot(r11.direction, camera.right()) / f11;
    const float sy = glm::dot(r00.direction, camera.up()) / f00;
    const float sy1 = glm::dot(r11.direction, camera.up()) / f11;
    for (std::uint32_t i = 0; i < soup.size(); ++i) {
      const SoupTriangle& tri = soup[i];
      float x_lo = std::numeric_limits<float>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
      bool everywhere = false;
      for (const Vec3& p : {tri.p0, tri.p1, tri.p2}) {
        const Vec3 d = p - camera.eye();
        const float f = glm::dot(d, camera.forward());
        const float extent = std::max(glm::length(d), 1e-30f);
        if (!(f > 1e-4f * extent)) {  // behind, on or barely in front of the eye plane
          everywhere = true;
          break;
        }
        const float px = (glm::dot(d, camera.right()) / f - sx) / (sx1 - sx) * static_cast<float>(camera.width());
        const float py = (glm::dot(d, camera.up()) / f - sy) / (sy1 - sy) * static_cast<float>(camera.height());
        x_lo = std::min(x_lo, px);
        x_hi = std::max(x_hi, px);
        y_lo = std::min(y_lo, py);
        y_hi = std::max(y_hi, py);
      }
      if (everywhere || !std::isfinite(x_lo + x_hi + y_lo + y_hi)) {
        everywhere_.push_back(i);
        continue;
      }
      // Two pixels of margin absorb every rounding above.
      const int tx0 = std::max(0, static_cast<int>(std::floor(x_lo)) - 2) / tile_;
      const int tx1 = std::min(camera.width() - 1, static_cast<int>(std::floor(x_hi)) + 2) / tile_;
      const int ty0 = std::max(0, static_cast<int>(std::floor(y_lo)) - 2) / tile_;
      const int ty1 = std::min(camera.height() - 1, static_cast<int>(std::floor(y_hi)) + 2) / tile_;
      if (x_hi < -2.0f || y_hi < -2.0f || x_lo > static_cast<float>(camera.width()) + 2.0f ||
          y_lo > static_cast<float>(camera.height()) + 2.0f) {
        continue;  // entirely off screen
      }
      for (int ty = ty0; ty <= ty1; ++ty) {
        for (int tx = tx0; tx <= tx1; ++tx) bins_[static_cast<std::size_t>(ty * tiles_x_ + tx)].push_back(i);
      }
    }
  }

  // Nearest hit of pixel (x, y)'s ray among every triangle that can reach it.
  Hit nearest(std::span<const SoupTriangle> soup, const Ray& ray, int x, int y, rt::TriangleTest test) const {
    const auto& bin = bins_[static_cast<std::size_t>((y / tile_) * tiles_x_ + x / tile_)];
    // Ties between the two lists may resolve differently from the plain
    // brute force; same_nearest accepts either triangle of a tie.
    return nearest_of(soup, everywhere_, ray, test, nearest_of(soup, bin, ray, test));
  }

 private:
  int tile_;
  int tiles_x_;
  int tiles_y_;
  std::vector<std::vector<std::uint32_t>> bins_;
  std::vector<std::uint32_t> everywhere_;
};

// Whether `ours` is a correct nearest hit given the reference `ref`: the
// same triangle at the same t (relative 1e-5), or, where two triangles are
// hit at the same t (a shared edge or vertex, coplanar overlap), another
// triangle that the ray really hits at that t.
inline bool same_nearest(const Hit& ours, const Hit& ref, std::span<const SoupTriangle> soup,
                         const Ray& ray, rt::TriangleTest test) {
  if (ours.valid() != ref.valid()) return false;
  if (!ref.valid()) return true;
  const float tol = 1e-5f * std::max(std::fabs(ref.t), 1e-30f);
  if (std::fabs(ours.t - ref.t) > tol) return false;
  if (ours.triangle_id == ref.triangle_id && ours.instance_id == ref.instance_id) return true;
  for (const SoupTriangle& tri : soup) {
    if (tri.triangle_id != ours.triangle_id || tri.instance_id != ours.instance_id) continue;
    rt::TriangleHit h;
    Ray unbounded = ray;
    unbounded.t_max = std::numeric_limits<float>::infinity();
    return test_one(tri, unbounded, test, unbounded.t_max, h) && std::fabs(h.t - ref.t) <= tol;
  }
  return false;
}

}  // namespace sinew::testing_support
