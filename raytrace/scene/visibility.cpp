#include "raytrace/scene/visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sinew::rt {
namespace {

using D3 = std::array<double, 3>;

D3 to_d(const Vec3& v) { return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)}; }
double dot(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 sub(const D3& a, const D3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
D3 add_scaled(const D3& a, double s, const D3& b) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }
D3 cross(const D3& a, const D3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const D3& a) { return std::sqrt(dot(a, a)); }
double norm1(const D3& a) { return std::fabs(a[0]) + std::fabs(a[1]) + std::fabs(a[2]); }
bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
float max_abs(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

}  // namespace

bool FrameCull::box_outside(const Plane& plane, const double lower[3], const double upper[3]) {
  // The box's nearest corner to the plane's inside, per axis.
  double nearest = 0.0;
  for (int a = 0; a < 3; ++a) nearest += plane.n[a] * (plane.n[a] >= 0.0 ? lower[a] : upper[a]);
  return nearest > plane.offset;
}

void FrameCull::grown(const Aabb& box, double lower[3], double upper[3]) const {
  for (int a = 0; a < 3; ++a) {
    lower[a] = static_cast<double>(box.lower[a]) - margin_;
    upper[a] = static_cast<double>(box.upper[a]) + margin_;
  }
}

bool FrameCull::begin(const FrameVisibility& view, float magnitude) {
  view_ = view;
  receivers_.clear();
  planes_.clear();
  shadows_ = false;
  if (!finite(view.eye) || !finite(view.forward) || !finite(view.right) || !finite(view.up) ||
      !(view.half_width > 0.0f && view.half_width < 1e6f) || !(view.half_height > 0.0f && view.half_height < 1e6f) ||
      !std::isfinite(magnitude) || view.light_count > kMaxViewLights) {
    return false;
  }
  double scale = std::max(static_cast<double>(magnitude), static_cast<double>(max_abs(view.eye)));
  for (std::uint32_t l = 0; l < view.light_count; ++l) {
    const ViewLight& light = view.lights[l];
    if (!finite(light.position) || !finite(light.direction) || !std::isfinite(light.radius) ||
        !(light.radius >= 0.0f) || !(light.angular_radius >= 0.0f && light.angular_radius < 1.5f)) {
      return false;
    }
    if (light.kind == ViewLight::Kind::kPoint) {
      scale = std::max(scale, static_cast<double>(max_abs(light.position)) + static_cast<double>(light.radius));
    } else if (!(norm(to_d(light.direction)) > 0.0)) {
      return false;  // no direction: its shadow rays are not bounded here
    }
  }
  if (!(std::isfinite(view.ao_reach) && view.ao_reach >= 0.0f)) return false;
  margin_ = kRelativeMargin * scale + static_cast<double>(std::numeric_limits<float>::min());

  // Camera rays: forward + a right + b up with |a| <= half_width. The side
  // planes n . (p - eye) <= 0 with n = right - A forward (and its three
  // twins), A the half extent widened well past the rounding of the rays'
  // directions and of the basis's orthogonality.
  const D3 f = to_d(view.forward), r = to_d(view.right), u = to_d(view.up), eye = to_d(view.eye);
  const double half_width = static_cast<double>(view.half_width), half_height = static_cast<double>(view.half_height);
  const double slack = 0x1.0p-20 * (1.0 + half_width + half_height);
  const double a = half_width * (1.0 + 0x1.0p-14) + slack;
  const double b = half_height * (1.0 + 0x1.0p-14) + slack;
  const D3 normals[4] = {add_scaled(r, -a, f), add_scaled({-r[0], -r[1], -r[2]}, -a, f), add_scaled(u, -b, f),
                         add_scaled({-u[0], -u[1], -u[2]}, -b, f)};
  for (int i = 0; i < 4; ++i) {
    frustum_[static_cast<std::size_t>(i)] = {{normals[i][0], normals[i][1], normals[i][2]}, dot(normals[i], eye)};
  }
  return true;
}

bool FrameCull::in_view(const Aabb& box) const {
  if (box.is_empty()) return false;
  double lower[3], upper[3];
  grown(box, lower, upper);
  for (const Plane& plane : frustum_) {
    if (box_outside(plane, lower, upper)) return false;
  }
  return true;
}

void FrameCull::add_receivers(const Aabb& box) {
  if (box.is_empty()) return;
  double lower[3], upper[3];
  grown(box, lower, upper);
  // Every corner inside the frustum: the box is its own visible part.
  bool inside = true;
  for (int c = 0; c < 8 && inside; ++c) {
    const D3 p{(c & 1) ? upper[0] : lower[0], (c & 2) ? upper[1] : lower[1], (c & 4) ? upper[2] : lower[2]};
    for (const Plane& plane : frustum_) inside = inside && dot({plane.n[0], plane.n[1], plane.n[2]}, p) <= plane.offset;
  }
  if (inside) {
    for (int c = 0; c < 8; ++c) {
      receivers_.push_back(
          {(c & 1) ? upper[0] : lower[0], (c & 2) ? upper[1] : lower[1], (c & 4) ? upper[2] : lower[2]});
    }
    return;
  }
  // Otherwise the vertices of the box cut by the frustum: every point where
  // three of the ten planes meet and which no plane cuts off (within a
  // rounding tolerance: a point slightly outside only widens the bound).
  Plane planes[10];
  for (int i = 0; i < 4; ++i) planes[i] = frustum_[static_cast<std::size_t>(i)];
  for (int a = 0; a < 3; ++a) {
    Plane lo, hi;
    lo.n[a] = -1.0;
    lo.offset = -lower[a];
    hi.n[a] = 1.0;
    hi.offset = upper[a];
    planes[4 + 2 * a] = lo;
    planes[5 + 2 * a] = hi;
  }
  for (int i = 0; i < 10; ++i) {
    for (int j = i + 1; j < 10; ++j) {
      for (int k = j + 1; k < 10; ++k) {
        const D3 ni{planes[i].n[0], planes[i].n[1], planes[i].n[2]};
        const D3 nj{planes[j].n[0], planes[j].n[1], planes[j].n[2]};
        const D3 nk{planes[k].n[0], planes[k].n[1], planes[k].n[2]};
        const D3 jk = cross(nj, nk), ki = cross(nk, ni), ij = cross(ni, nj);
        const double det = dot(ni, jk);
        if (!(std::fabs(det) > 1e-12 * norm(ni) * norm(nj) * norm(nk))) continue;
        D3 p{0.0, 0.0, 0.0};
        p = add_scaled(p, planes[i].offset / det, jk);
        p = add_scaled(p, planes[j].offset / det, ki);
        p = add_scaled(p, planes[k].offset / det, ij);
        const double size = std::max({std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])});
        bool feasible = std::isfinite(size);
        for (int q = 0; q < 10 && feasible; ++q) {
          const D3 nq{planes[q].n[0], planes[q].n[1], planes[q].n[2]};
          feasible = dot(nq, p) <= planes[q].offset + 1e-9 * (std::fabs(planes[q].offset) + norm1(nq) * size);
        }
        if (feasible) receivers_.push_back(p);
      }
    }
  }
}

void FrameCull::finish_receivers() {
  planes_.clear();
  shadows_ = view_.shadows && view_.light_count > 0 && !receivers_.empty();
  if (!shadows_) return;
  D3 centre{0.0, 0.0, 0.0};
  for (const D3& p : receivers_) centre = add_scaled(centre, 1.0 / static_cast<double>(receivers_.size()), p);

  // The fixed directions: the axes, the frustum's sides and the view axis.
  std::array<D3, 20> fixed{};  // 12 fixed, then room for a directional light's 8 sides
  for (std::size_t a = 0; a < 3; ++a) {
    fixed[2 * a][a] = 1.0;
    fixed[2 * a + 1][a] = -1.0;
  }
  for (std::size_t i = 0; i < 4; ++i) fixed[6 + i] = {frustum_[i].n[0], frustum_[i].n[1], frustum_[i].n[2]};
  const D3 f = to_d(view_.forward);
  fixed[10] = f;
  fixed[11] = {-f[0], -f[1], -f[2]};

  // A plane with normal n holds the whole volume when its offset is the
  // largest n . x over the volume's generators: the light (point lights)
  // and every receiver corner. A directional light's volume runs to
  // infinity along its direction, so only normals pointing against it
  // (n . d < 0, by a margin over the rounding of the renderer's direction)
  // bound it.
  auto add_plane = [&](const D3& n, const ViewLight& light) {
    double offset = -std::numeric_limits<double>::infinity();
    for (const D3& p : receivers_) offset = std::max(offset, dot(n, p));
    if (light.kind == ViewLight::Kind::kPoint) {
      // The light's farthest point along n: its centre plus its radius.
      offset = std::max(offset, dot(n, to_d(light.position)) + static_cast<double>(light.radius) * norm(n));
    }
    if (std::isfinite(offset)) planes_.push_back({{n[0], n[1], n[2]}, offset});
  };
  // Normals around an axis `a` (unit): four sides and four diagonals.
  auto around = [](const D3& a, D3 out[8]) {
    const D3 helper = std::fabs(a[0]) < 0.6 ? D3{1.0, 0.0, 0.0} : D3{0.0, 1.0, 0.0};
    D3 u = cross(a, helper);
    u = add_scaled({0.0, 0.0, 0.0}, 1.0 / norm(u), u);
    const D3 v = cross(a, u);
    const D3 nu{-u[0], -u[1], -u[2]}, nv{-v[0], -v[1], -v[2]};
    out[0] = u, out[1] = nu, out[2] = v, out[3] = nv;
    out[4] = add_scaled(u, 1.0, v), out[5] = add_scaled(u, -1.0, v), out[6] = add_scaled(nu, 1.0, v),
    out[7] = add_scaled(nu, -1.0, v);
  };

  for (std::uint32_t l = 0; l < view_.light_count; ++l) {
    light_begin_[l] = static_cast<std::uint32_t>(planes_.size());
    const ViewLight& light = view_.lights[l];
    if (light.kind == ViewLight::Kind::kPoint) {
      const D3 lp = to_d(light.position);
      for (std::size_t i = 0; i < 12; ++i) add_plane(fixed[i], light);
      // An area light's volume has no single apex: the fixed planes hold it.
      if (light.radius > 0.0f) continue;
      // A pyramid from the light around the receivers: for each side w, the
      // steepest slope (p - L) . w / (p - L) . a of a receiver, when every
      // receiver lies ahead of the light along a.
      D3 a = sub(centre, lp);
      const double length = norm(a);
      if (!(length > 0.0) || !std::isfinite(length)) continue;
      a = add_scaled({0.0, 0.0, 0.0}, 1.0 / length, a);
      bool ahead = true;
      for (const D3& p : receivers_) {
        const D3 q = sub(p, lp);
        ahead = ahead && dot(q, a) > 1e-6 * norm(q);
      }
      if (!ahead) continue;
      D3 sides[8];
      around(a, sides);
      for (const D3& w : sides) {
        double slope = -std::numeric_limits<double>::infinity();
        for (const D3& p : receivers_) {
          const D3 q = sub(p, lp);
          slope = std::max(slope, dot(q, w) / dot(q, a));
        }
        add_plane(add_scaled(w, -slope, a), light);
      }
    } else {
      D3 d = to_d(light.direction);
      d = add_scaled({0.0, 0.0, 0.0}, 1.0 / norm(d), d);
      add_plane({-d[0], -d[1], -d[2]}, light);
      around(d, &fixed[12]);
      // The sun's rays arrive within its angular radius of d: a plane holds
      // them when its normal leans that far and more past perpendicular.
      const double lean = std::tan(static_cast<double>(light.angular_radius) * (1.0 + 0x1.0p-10));
      for (const D3& n : fixed) {
        // Against the light: n . d = -2^-16 |n| after the projection (and
        // for the sun, its lean of the rest of n more).
        const double size = norm(n);
        const D3 across = add_scaled(n, -dot(n, d), d);
        const D3 projected = add_scaled(n, -dot(n, d) - 0x1.0p-16 * size - lean * norm(across), d);
        if (!(norm(projected) > 1e-3 * size)) continue;
        if (!(dot(projected, d) < 0.0)) continue;
        add_plane(projected, light);
      }
    }
  }
  light_begin_[view_.light_count] = static_cast<std::uint32_t>(planes_.size());
}

bool FrameCull::casts_into_view(const Aabb& box) const {
  if (box.is_empty()) return false;
  double lower[3], upper[3];
  grown(box, lower, upper);
  if (view_.ao_reach > 0.0f) {
    // An ambient occlusion ray starts on a point in view and ends within
    // ao_reach of it: the box grown by that much meets the frustum.
    const double reach = static_cast<double>(view_.ao_reach) * (1.0 + 0x1.0p-10);
    double far_lower[3], far_upper[3];
    for (int a = 0; a < 3; ++a) {
      far_lower[a] = lower[a] - reach;
      far_upper[a] = upper[a] + reach;
    }
    bool outside = false;
    for (const Plane& plane : frustum_) outside = outside || box_outside(plane, far_lower, far_upper);
    if (!outside) return true;
  }
  if (!shadows_) return false;
  for (std::uint32_t l = 0; l < view_.light_count; ++l) {
    bool outside = false;
    for (std::uint32_t i = light_begin_[l]; i < light_begin_[l + 1] && !outside; ++i) {
      outside = box_outside(planes_[i], lower, upper);
    }
    if (!outside) return true;
  }
  return false;
}

}  // namespace sinew::rt
