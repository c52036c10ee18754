// GridFrusta: the frusta of a camera packet's groups, separable. In the
// camera's basis one 4x2-pixel block's directions fill a rectangle of slopes,
// so every block of a column shares two side planes and every block of a row
// the other two: a triangle costs one plane pair per column and per row
// (four eight-lane evaluations for up to 8x8 blocks), and reaches the
// crossings of the columns and rows that do not cut it off. Margins as
// group_frusta.h. docs/RAYTRACE.md, "The camera's grid".
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "raytrace/cull/group_frusta.h"
#include "runtime/math/aabb.h"
#include "runtime/math/float8.h"
#include "runtime/math/types.h"

namespace sinew::rt {

class GridFrusta {
 public:
  static constexpr int kMaxColumns = 8;
  static constexpr int kMaxRows = 8;

  // The slabs of `groups` groups (group g at column g % columns, row
  // g / columns) whose rays leave `apex` along the directions q(g) (a
  // float[3][8]) of lanes(g), slopes measured along `u` and `v` over `c`
  // (a camera's right, up and forward). False, culling nothing, when the
  // grid does not fit kMaxColumns x kMaxRows or a lane is not well in front
  // of c (more than about 75 degrees off it, or not finite).
  template <class Q, class Lanes>
  bool build(const Vec3& apex, const Vec3& c, const Vec3& u, const Vec3& v, int groups, int columns, Q&& q,
             Lanes&& lanes) {
    on_ = false;
    if (columns < 1 || columns > kMaxColumns || groups < 1) return false;
    const int rows = (groups + columns - 1) / columns;
    if (rows > kMaxRows) return false;
    // Each column's and row's slopes gathered lane-wise first, reduced once
    // at the end (a reduction per group and side cost more than the rest).
    const float big = std::numeric_limits<float>::max();
    Float8 a_lo[kMaxColumns], a_hi[kMaxColumns], b_lo[kMaxRows], b_hi[kMaxRows];
    std::fill(std::begin(a_lo), std::end(a_lo), Float8(big));
    std::fill(std::begin(a_hi), std::end(a_hi), Float8(-big));
    std::fill(std::begin(b_lo), std::end(b_lo), Float8(big));
    std::fill(std::begin(b_hi), std::end(b_hi), Float8(-big));
    const Float8 zero(0.0f);
    const auto along = [](const Vec3x8& d, const Vec3& w) {
      return d.x * Float8(w.x) + d.y * Float8(w.y) + d.z * Float8(w.z);
    };
    for (int g = 0; g < groups; ++g) {
      const std::uint32_t l = lanes(g) & 0xFFu;
      if (l == 0) continue;
      const Mask8 use = Mask8::from_bits(l);
      const float (&dq)[3][8] = q(g);
      const Vec3x8 d{select(use, Float8::load(dq[0]), zero), select(use, Float8::load(dq[1]), zero),
                     select(use, Float8::load(dq[2]), zero)};
      const Float8 dc = along(d, c);
      const Mask8 in_front = (dc > zero) & (dc * dc > Float8(0.0625f) * dot(d, d)) & is_finite(dot(d, d));
      if ((in_front | !use).bits() != 0xFFu) return false;
      const Float8 inv_dc = Float8(1.0f) / select(use, dc, Float8(1.0f));
      const Float8 a = along(d, u) * inv_dc, b = along(d, v) * inv_dc;
      const int column = g % columns, row = g / columns;
      a_lo[column] = min(a_lo[column], select(use, a, Float8(big)));
      a_hi[column] = max(a_hi[column], select(use, a, Float8(-big)));
      b_lo[row] = min(b_lo[row], select(use, b, Float8(big)));
      b_hi[row] = max(b_hi[row], select(use, b, Float8(-big)));
    }
    apex_ = apex;
    apex_magnitude_ = magnitude(apex);
    columns_ = columns;
    rows_ = rows;
    // Outside: n . (p - apex) > 0. Lanes without slopes (no lane in their
    // column or row) keep zero normals, which never cut.
    for (Planes* p : {&column_hi_, &column_lo_, &row_hi_, &row_lo_, &outer_}) *p = Planes{};
    float a_min = big, a_max = -big, b_min = big, b_max = -big;
    // Column (row) i's pair of planes holds its lanes' slopes along `side`
    // (u for columns, v for rows), and the slopes' overall range grows.
    const auto set_pair = [&](Planes& upper, Planes& lower, int i, Float8 lo8, Float8 hi8, const Vec3& side,
                              float& least, float& most) {
      const float lo = reduce_min(lo8), hi = reduce_max(hi8);
      if (lo > hi) return;
      upper.set(i, side - (hi + grown_slope(hi)) * c);
      lower.set(i, (lo - grown_slope(lo)) * c - side);
      least = std::min(least, lo);
      most = std::max(most, hi);
    };
    for (int i = 0; i < columns; ++i) set_pair(column_hi_, column_lo_, i, a_lo[i], a_hi[i], u, a_min, a_max);
    for (int i = 0; i < rows; ++i) set_pair(row_hi_, row_lo_, i, b_lo[i], b_hi[i], v, b_min, b_max);
    // The whole packet's four sides, the same planes at its extreme slopes
    // (none without a lane).
    if (a_min <= a_max && b_min <= b_max) {
      outer_.set(0, u - (a_max + grown_slope(a_max)) * c);
      outer_.set(1, (a_min - grown_slope(a_min)) * c - u);
      outer_.set(2, v - (b_max + grown_slope(b_max)) * c);
      outer_.set(3, (b_min - grown_slope(b_min)) * c - v);
    }
    on_ = true;
    return true;
  }

  bool on() const { return on_; }
  void reset() { on_ = false; }

  // The groups of `groups` whose column and row the triangle may reach.
  std::uint64_t reached(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint64_t groups) const {
    const Vec3 x0 = p0 - apex_, x1 = p1 - apex_, x2 = p2 - apex_;
    const float corners = std::max({magnitude(p0), magnitude(p1), magnitude(p2)});
    return uncut(groups, corners, [&](const float (&n)[3][8]) {
      const Float8 nx = Float8::load(n[0]), ny = Float8::load(n[1]), nz = Float8::load(n[2]);
      const auto side = [&](const Vec3& x) { return (nx * Float8(x.x) + ny * Float8(x.y)) + nz * Float8(x.z); };
      return min(min(side(x0), side(x1)), side(x2));
    });
  }

  // reached() for the triangles of `lanes` of `t` (bit i: triangle i),
  // eight at a time, the same decisions per triangle: out[i] gets the
  // groups of `groups` triangle i may reach, 0 for the other lanes. Only
  // the columns and rows of `groups` are tested.
  void reached8(const TriangleLanes8& t, std::uint32_t lanes, std::uint64_t groups, std::uint64_t (&out)[8]) const {
    std::fill(std::begin(out), std::end(out), std::uint64_t{0});
    if (!on_) {
      for (std::uint32_t m = lanes; m != 0; m &= m - 1) out[std::countr_zero(m)] = groups;
      return;
    }
    const detail::ApexTriangles8 x(t, apex_, apex_magnitude_);
    const auto cut = [&](const Planes& p, int i) {
      return (x.nearest(p.n[0][i], p.n[1][i], p.n[2][i]) > Float8(p.scale[i]) * x.margin).bits();
    };
    lanes &= ~(cut(outer_, 0) | cut(outer_, 1) | cut(outer_, 2) | cut(outer_, 3));
    if (lanes == 0) return;
    std::uint32_t columns = 0, rows = 0;
    for (std::uint64_t m = groups; m != 0; m &= m - 1) {
      const int g = std::countr_zero(m);
      columns |= 1u << (g % columns_);
      rows |= 1u << (g / columns_);
    }
    // Per triangle the columns and the rows it reaches.
    std::uint32_t lane_columns[8] = {}, lane_rows[8] = {};
    for (; columns != 0; columns &= columns - 1) {
      const int c = std::countr_zero(columns);
      for (std::uint32_t m = lanes & ~(cut(column_hi_, c) | cut(column_lo_, c)); m != 0; m &= m - 1) {
        lane_columns[std::countr_zero(m)] |= 1u << c;
      }
    }
    for (; rows != 0; rows &= rows - 1) {
      const int r = std::countr_zero(rows);
      for (std::uint32_t m = lanes & ~(cut(row_hi_, r) | cut(row_lo_, r)); m != 0; m &= m - 1) {
        lane_rows[std::countr_zero(m)] |= 1u << r;
      }
    }
    for (std::uint32_t m = lanes; m != 0; m &= m - 1) {
      const int i = std::countr_zero(m);
      std::uint64_t reach = 0;
      for (std::uint32_t r = lane_rows[i]; r != 0; r &= r - 1) {
        reach |= std::uint64_t{lane_columns[i]} << (columns_ * std::countr_zero(r));
      }
      out[i] = reach & groups;
    }
  }

  // The groups of `groups` whose column and row may reach `box` (its corner
  // nearest each plane, box_plane_nearest: at least every group a triangle
  // inside it reaches; an empty or non-finite box is reached by all).
  std::uint64_t box_reached(const Aabb& box, std::uint64_t groups) const {
    const Vec3 lo = box.lower - apex_, hi = box.upper - apex_;
    const float corners = std::max(magnitude(box.lower), magnitude(box.upper));
    return uncut(groups, corners, [&](const float (&n)[3][8]) {
      return box_plane_nearest(Float8::load(n[0]), Float8::load(n[1]), Float8::load(n[2]), lo, hi);
    });
  }

 private:
  // nearest(n) is the shape's least signed distance to each of eight
  // planes; a plane cuts it off beyond the margin for coordinates up to
  // `corners`. The packet's own sides first: most shapes a packet's walk
  // meets lie outside it (two in three of the triangles of Cally's leaves
  // at 213,888 triangles), and one evaluation settles them instead of four.
  template <class Nearest>
  std::uint64_t uncut(std::uint64_t groups, float corners, Nearest&& nearest) const {
    if (!on_) return groups;
    const Float8 margin = cull_margin(corners, apex_magnitude_);
    const auto cut = [&](const Planes& p) { return (nearest(p.n) > Float8::load(p.scale) * margin).bits(); };
    if (cut(outer_) != 0) return 0;
    const std::uint64_t columns = ~(cut(column_hi_) | cut(column_lo_)) & ((1u << columns_) - 1u);
    std::uint32_t rows = ~(cut(row_hi_) | cut(row_lo_)) & ((1u << rows_) - 1u);
    std::uint64_t out = 0;
    for (; rows != 0; rows &= rows - 1) out |= columns << (columns_ * std::countr_zero(rows));
    return out & groups;
  }

  // Up to eight planes side by side, plane i in lane i. Lanes without one
  // keep zero normals, which never cut.
  struct Planes {
    alignas(32) float n[3][8] = {};
    alignas(32) float scale[8] = {};
    void set(int i, const Vec3& plane) {
      n[0][i] = plane.x;
      n[1][i] = plane.y;
      n[2][i] = plane.z;
      // |n|_1 bounds n . e for |e| <= margin per coordinate; slightly more
      // for the rounding of the products.
      scale[i] = 1.001f * (std::fabs(plane.x) + std::fabs(plane.y) + std::fabs(plane.z));
    }
  };
  static float magnitude(const Vec3& p) { return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}); }

  bool on_ = false;
  Vec3 apex_{0.0f};
  float apex_magnitude_ = 0.0f;
  int columns_ = 1;
  int rows_ = 1;
  // Lane i: column (row) i's plane on the side of rising slopes (hi) and
  // on the other side (lo); the packet's sides in lanes 0 to 3 of outer_.
  Planes column_hi_, column_lo_, row_hi_, row_lo_, outer_;
};

}  // namespace sinew::rt
