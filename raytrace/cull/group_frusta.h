// GroupFrusta: for each group of eight rays from one apex (camera rays, a
// point light's shadow rays), four planes through the apex that hold its
// rays, and for rays that end (shadow rays) a far plane. Segments that
// start anywhere within a radius of the apex (an area light's samples) get
// the four side planes tilted to hold them (tilt_side). A triangle whose
// corners all lie beyond one plane is missed by the whole group, so a leaf's
// triangle is tested only by the groups it reaches. Also the packet's own
// frustum, tested first, and each group's slab in the packet's basis
// (shadow packets). docs/RAYTRACE.md, "Group frusta" and "Shadow slabs";
// kFrustumMargin's derivation under "Numerical margins".
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "runtime/math/aabb.h"
#include "runtime/math/float8.h"
#include "runtime/math/types.h"

namespace sinew::rt {

// The frusta's one relative margin, 2^-16 (the header comment above derives
// it). Shared by the group frusta, the camera grid (grid_frusta.h) and the
// tile cone (cull/static_tiles.h), in three roles: a side plane is grown
// away from its rays by kFrustumMargin of their slope (grown_slope), a far
// plane pushed out by kFrustumMargin of its reach (far_offset), and a shape
// is culled only beyond kFrustumMargin of the coordinate magnitudes
// involved (cull_margin).
inline constexpr float kFrustumMargin = 0x1.0p-16f;

// The growth of a bounding slope s away from the rays it bounds.
inline float grown_slope(float s) { return kFrustumMargin * (1.0f + std::fabs(s)); }
inline Float8 grown_slope(Float8 s) { return Float8(kFrustumMargin) * (Float8(1.0f) + abs(s)); }

// A far plane's offset from the largest reach of its rays along its normal.
inline float far_offset(float reach) { return reach * (1.0f + kFrustumMargin); }
inline Float8 far_offset(Float8 reach) { return reach * Float8(1.0f + kFrustumMargin); }

// A side plane n . x <= 0 of segments' far ends x = q (relative to the
// apex, each q with n . q <= 0 and depth c . q <= far along the unit
// centre c) made to hold the whole segments when each starts at some w
// within `radius` of the apex: a point (1 - t) w + t q has
//   n . x + alpha c . x <= (1 - t)(R |n| + alpha R) + t alpha far,
// so the plane n + alpha c with offset max(R |n| + alpha R, alpha far)
// holds it for any alpha >= 0; alpha = R |n| / (far - R) makes both terms
// equal: the plane is tangent to the ball at the apex and meets the
// deepest ends. `far` must exceed the radius (set_block asks for twice);
// both offsets' sums are grown as far planes are.
struct TiltedSide {
  Vec3x8 n;
  Float8 offset;
};
inline TiltedSide tilt_side(const Vec3x8& n, const Vec3x8& c, Float8 far, float radius) {
  const Float8 r(radius);
  const Float8 rn = r * sqrt(dot(n, n));
  const Float8 alpha = rn / max(far - r, Float8(std::numeric_limits<float>::min()));
  return {n + alpha * c, far_offset(max(rn + alpha * r, alpha * far))};
}
// tilt_side for one plane; returns the slope alpha added along c.
inline float tilt_side(Vec3& n, float& offset, const Vec3& c, float far, float radius) {
  const float rn = radius * std::sqrt(glm::dot(n, n));
  const float alpha = rn / std::max(far - radius, std::numeric_limits<float>::min());
  n = n + alpha * c;
  offset = far_offset(std::max(rn + alpha * radius, alpha * far));
  return alpha;
}

// How far beyond a plane a shape must lie to be culled, per unit of the
// plane's L1 norm: kFrustumMargin of the coordinate magnitudes involved (its
// corners' largest and the apex's).
inline Float8 cull_margin(float corners, float apex_magnitude) {
  return Float8(kFrustumMargin * (corners + apex_magnitude));
}

// The least of n . x over the box [lo, hi] (relative to an apex) for eight
// planes n: per axis the nearer corner's product. Rounding is monotone, so
// it never exceeds (n.x x + n.y y) + n.z z, the sum the triangle culls of
// GroupFrusta and GridFrusta take at a corner, at any point of the box: a
// box reaches every group a triangle inside it reaches.
inline Float8 box_plane_nearest(Float8 nx, Float8 ny, Float8 nz, const Vec3& lo, const Vec3& hi) {
  const auto nearer = [](Float8 n, float l, float h) { return min(n * Float8(l), n * Float8(h)); };
  return (nearer(nx, lo.x, hi.x) + nearer(ny, lo.y, hi.y)) + nearer(nz, lo.z, hi.z);
}

// Up to eight triangles side by side, for culling a leaf's triangles eight
// at a time (GroupFrusta::reached8, GridFrusta::reached8): coordinate a of
// corner k of triangle i in p[k][a][i].
struct TriangleLanes8 {
  alignas(32) float p[3][3][8];
  Vec3 corner(int k, int i) const { return Vec3(p[k][0][i], p[k][1][i], p[k][2][i]); }
};

namespace detail {

// Eight triangles' corners relative to an apex, and each triangle's cull
// margin: per lane the values reached() takes for one triangle (the same
// differences, cull_margin of its corners' largest magnitude).
struct ApexTriangles8 {
  Vec3x8 x[3];
  Float8 margin;

  ApexTriangles8(const TriangleLanes8& t, const Vec3& apex, float apex_magnitude) {
    Float8 corners(0.0f);
    for (int k = 0; k < 3; ++k) {
      const Float8 px = Float8::load(t.p[k][0]), py = Float8::load(t.p[k][1]), pz = Float8::load(t.p[k][2]);
      x[k] = Vec3x8{px - Float8(apex.x), py - Float8(apex.y), pz - Float8(apex.z)};
      corners = max(corners, max(max(abs(px), abs(py)), abs(pz)));
    }
    margin = Float8(kFrustumMargin) * (corners + Float8(apex_magnitude));
  }

  // Per triangle, the least of n . x over its corners, each summed
  // (n.x x + n.y y) + n.z z as the one-triangle culls sum it.
  Float8 nearest(float nx, float ny, float nz) const {
    const Float8 a(nx), b(ny), c(nz);
    const auto side = [&](const Vec3x8& w) { return (a * w.x + b * w.y) + c * w.z; };
    return min(min(side(x[0]), side(x[1])), side(x[2]));
  }
};

}  // namespace detail

template <int kMaxGroups>
class GroupFrusta {
  static_assert(kMaxGroups % 8 == 0);

 public:
  // A packet of `groups` groups whose rays' points are apex + s q, s >= 0;
  // every group starts with no frustum (it reaches every triangle). With a
  // radius, the rays are segments from points within it of the apex to
  // apex + reach q, and only frusta with far planes are built, their sides
  // tilted to hold the segments (tilt_side).
  void reset(const Vec3& apex, int groups, float radius = 0.0f) {
    apex_ = apex;
    apex_radius_ = radius;
    apex_magnitude_ = std::max({std::fabs(apex.x), std::fabs(apex.y), std::fabs(apex.z)});
    groups_ = std::clamp(groups, 0, kMaxGroups);
    // The planes themselves are left as they are: reached() reads only
    // those of groups marked built.
    sides_.fill(0);
    far_.fill(0);
    bound_groups_ = 0;
    slab_groups_ = 0;
  }

  // Group g's frustum around the directions q of `lanes` (structure of
  // arrays, eight lanes; other lanes are not read). A group whose rays
  // spread over more than about 75 degrees from their mean keeps none.
  // With `reach` (per lane, the largest s of its points apex + s q) the
  // frustum also gets a far plane: a triangle beyond every lane's end point
  // (a shadow ray's shadowed point) cannot block it.
  void set_group(int g, const float (&q)[3][8], std::uint32_t lanes, const float* reach = nullptr) {
    if (lanes == 0 || g < 0 || g >= groups_) return;
    const auto directions = [&](int) -> const float (&)[3][8] { return q; };
    const auto lanes_of = [&](int) { return lanes; };
    const std::uint32_t block = 1u << (g % 8);
    if (reach != nullptr) {
      const auto reach_of = [&](int, float* out) { std::copy_n(reach, 8, out); };
      set_block<true>(g - g % 8, block, 1.0f, directions, lanes_of, reach_of);
    } else {
      const auto no_reach = [](int, float*) {};
      set_block<false>(g - g % 8, block, 1.0f, directions, lanes_of, no_reach);
    }
  }

  // set_group for every group of `groups`, with group g's directions
  // sign * q(g) (a float[3][8]), its lanes lanes(g) and, with kFar, its
  // per-lane reach written by reach(g, out): eight groups at a time, one
  // group per SIMD lane, so a packet's frusta cost about what one does.
  template <bool kFar, class Q, class Lanes, class Reach>
  void set_groups(std::uint64_t groups, float sign, Q&& q, Lanes&& lanes, Reach&& reach) {
    groups &= live_groups();
    for (int base = 0; base < groups_; base += 8) {
      const auto block = static_cast<std::uint32_t>(groups >> base) & 0xFFu;
      if (block != 0) set_block<kFar>(base, block, sign, q, lanes, reach);
    }
  }

  // One frustum around every ray of `groups` (set_groups' arguments), the
  // same construction as a group's over all their lanes: reached() tests
  // a triangle against it first, and most triangles a packet's cells hold
  // lie outside it (seven in ten on Cally), so they cost one plane test
  // instead of one per block of eight groups. Rays spread over more than
  // about 75 degrees leave the packet without one.
  template <bool kFar, class Q, class Lanes, class Reach>
  void set_bound(std::uint64_t groups, float sign, Q&& q, Lanes&& lanes, Reach&& reach) {
    bound_groups_ = 0;
    groups &= live_groups();
    if (groups == 0 || (!kFar && apex_radius_ > 0.0f)) return;
    const Float8 zero(0.0f);
    const auto directions = [&](int g, std::uint32_t use_bits) {
      const Mask8 use = Mask8::from_bits(use_bits);
      const float (&d)[3][8] = q(g);
      return Vec3x8{select(use, Float8(sign) * Float8::load(d[0]), zero),
                    select(use, Float8(sign) * Float8::load(d[1]), zero),
                    select(use, Float8(sign) * Float8::load(d[2]), zero)};
    };
    Vec3x8 sum{zero, zero, zero};
    int first = -1;
    for (std::uint64_t m = groups; m != 0; m &= m - 1) {
      const int g = std::countr_zero(m);
      const std::uint32_t l = lanes(g);
      if (l == 0) continue;
      if (first < 0) first = g;
      sum = sum + directions(g, l);
    }
    if (first < 0) return;
    const Vec3 c = normalized({reduce_add(sum.x), reduce_add(sum.y), reduce_add(sum.z)});
    if (!(c.x == c.x)) return;
    // u along a pixel row of the first group (a camera block's lanes are
    // two rows of four): from its first lane to the one three on.
    const std::uint32_t first_lanes = lanes(first);
    const int i0 = std::countr_zero(first_lanes);
    const int i1 = i0 + 3 < 8 && (first_lanes >> (i0 + 3) & 1u) ? i0 + 3 : 31 - std::countl_zero(first_lanes);
    const float (&f)[3][8] = q(first);
    Vec3 u, v;
    if (!row_basis(c, sign * Vec3(f[0][i1] - f[0][i0], f[1][i1] - f[1][i0], f[2][i1] - f[2][i0]), u, v)) return;
    const float big = std::numeric_limits<float>::max();
    Float8 a_lo(big), a_hi(-big), b_lo(big), b_hi(-big), far(0.0f);
    // Each group's own slab in this basis too (slab_groups_, reached()).
    slab_groups_ = 0;
    const float u1 = l1(u), v1 = l1(v), c1 = l1(c);
    for (std::uint64_t m = groups; m != 0; m &= m - 1) {
      const int g = std::countr_zero(m);
      const std::uint32_t l = lanes(g);
      // A group without lanes has no rays: an empty slab cuts everything.
      slab_[0][g] = big;
      slab_[1][g] = -big;
      slab_[2][g] = big;
      slab_[3][g] = -big;
      slab_far_[g] = kFar ? -big : big;
      if (l == 0) continue;
      const Mask8 use = Mask8::from_bits(l);
      Float8 a, b, dc;
      if (!slopes(directions(g, l), use, c, u, v, a, b, dc)) return;
      const Float8 ga_lo = select(use, a, Float8(big)), ga_hi = select(use, a, Float8(-big));
      const Float8 gb_lo = select(use, b, Float8(big)), gb_hi = select(use, b, Float8(-big));
      a_lo = min(a_lo, ga_lo);
      a_hi = max(a_hi, ga_hi);
      b_lo = min(b_lo, gb_lo);
      b_hi = max(b_hi, gb_hi);
      float group_offset = big;
      if constexpr (kFar) {
        alignas(32) float r[8] = {};
        reach(g, r);
        const Float8 group_far = select(use, Float8::load(r) * dc, zero);
        far = max(far, group_far);
        const float offset = far_offset(reduce_max(group_far));
        group_offset = std::isfinite(offset) ? offset : big;
        slab_far_[g] = group_offset;
      }
      if (apex_radius_ > 0.0f && !(group_offset > 2.0f * apex_radius_)) return;
      const float ranges[4] = {reduce_min(ga_lo), reduce_max(ga_hi), reduce_min(gb_lo), reduce_max(gb_hi)};
      for (int i = 0; i < 4; ++i) {
        const bool low = i % 2 == 0;
        float grown = low ? ranges[i] - grown_slope(ranges[i]) : ranges[i] + grown_slope(ranges[i]);
        slab_offset_[i][g] = 0.0f;
        if (apex_radius_ > 0.0f) {
          // The side's plane, (u or v) - grown c on the high side and its
          // negation on the low, tilted by alpha c: the slope moves in.
          const Vec3& w = i < 2 ? u : v;
          Vec3 n = low ? grown * c - w : w - grown * c;
          const float alpha = tilt_side(n, slab_offset_[i][g], c, group_offset, apex_radius_);
          grown = low ? grown + alpha : grown - alpha;
        }
        slab_[i][g] = grown;
        // |n|_1 of the side's plane (u or v minus grown times c), as store_planes.
        slab_scale_[i][g] = 1.001f * ((i < 2 ? u1 : v1) + std::fabs(grown) * c1);
      }
    }
    slab_basis_[0] = c;
    slab_basis_[1] = u;
    slab_basis_[2] = v;
    slab_far_scale_ = 1.001f * c1;
    slab_groups_ = groups;
    const float alo = reduce_min(a_lo), ahi = reduce_max(a_hi), blo = reduce_min(b_lo), bhi = reduce_max(b_hi);
    Vec3 planes[4] = {u - (ahi + grown_slope(ahi)) * c, (alo - grown_slope(alo)) * c - u, v - (bhi + grown_slope(bhi)) * c,
                      (blo - grown_slope(blo)) * c - v};
    float side_offsets[4] = {};
    const float far_reach = far_offset(reduce_max(far));
    if (apex_radius_ > 0.0f) {
      for (int i = 0; i < 4; ++i) tilt_side(planes[i], side_offsets[i], c, far_reach, apex_radius_);
    }
    // Lane i: plane i (the unused lanes' zero normals never cut).
    for (int a = 0; a < 3; ++a) std::fill(std::begin(bound_n_[a]), std::end(bound_n_[a]), 0.0f);
    std::fill(std::begin(bound_scale_), std::end(bound_scale_), 0.0f);
    std::fill(std::begin(bound_offset_), std::end(bound_offset_), 0.0f);
    const auto set = [&](int i, const Vec3& n, float offset) {
      bound_n_[0][i] = n.x;
      bound_n_[1][i] = n.y;
      bound_n_[2][i] = n.z;
      bound_scale_[i] = 1.001f * (std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z));
      bound_offset_[i] = offset;
    };
    for (int i = 0; i < 4; ++i) set(i, planes[i], side_offsets[i]);
    if constexpr (kFar) {
      if (std::isfinite(far_reach)) set(4, c, far_reach);
    }
    bound_groups_ = groups;
  }

  // The groups of `groups` whose frustum may reach `box` (an object's box,
  // before its lanes are clipped to it; a leaf's current triangles'). A box
  // lies wholly beyond a plane when its corner nearest the plane does; the
  // same margin as reached() covers the rounding of that corner's distance,
  // and box_plane_nearest() takes it as reached() takes a point, so a box reaches
  // every group a triangle inside it reaches. A box that is empty or not
  // finite is reached by every group (its distances are NaN or -inf).
  std::uint64_t box_reached(const Aabb& box, std::uint64_t groups) const {
    const Vec3 lo = box.lower - apex_, hi = box.upper - apex_;
    const float corners = std::max(magnitude(box.lower), magnitude(box.upper));
    return packet_then_groups(
        groups, corners, [&](Float8 nx, Float8 ny, Float8 nz) { return box_plane_nearest(nx, ny, nz, lo, hi); },
        [&] { return slabs_box_uncut(groups, corners, lo, hi); });
  }

  // The groups of `groups` whose frustum the triangle may reach.
  std::uint64_t reached(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint64_t groups) const {
    const Vec3 x0 = p0 - apex_, x1 = p1 - apex_, x2 = p2 - apex_;
    const float corners = std::max({magnitude(p0), magnitude(p1), magnitude(p2)});
    const auto nearest = [&](Float8 nx, Float8 ny, Float8 nz) {
      const auto side = [&](const Vec3& x) { return (nx * Float8(x.x) + ny * Float8(x.y)) + nz * Float8(x.z); };
      return min(min(side(x0), side(x1)), side(x2));
    };
    return packet_then_groups(groups, corners, nearest, [&] { return slabs_uncut(groups, corners, x0, x1, x2); });
  }

  // reached() for the triangles of `lanes` of `t` (bit i: triangle i),
  // eight at a time: out[i] gets the groups of `groups` whose own frustum
  // triangle i may reach, decided per triangle and group as reached()
  // decides it there, without the packet's frustum first (the caller's
  // leaf box has already picked `groups`: its test would cost about one
  // group's). out[i] is 0 for the other lanes. With slabs on, reached()
  // per triangle.
  void reached8(const TriangleLanes8& t, std::uint32_t lanes, std::uint64_t groups, std::uint64_t (&out)[8]) const {
    std::fill(std::begin(out), std::end(out), std::uint64_t{0});
    if (slabs_on_) {
      for (std::uint32_t m = lanes; m != 0; m &= m - 1) {
        const int i = std::countr_zero(m);
        out[i] = reached(t.corner(0, i), t.corner(1, i), t.corner(2, i), groups);
      }
      return;
    }
    groups &= live_groups();
    const detail::ApexTriangles8 x(t, apex_, apex_magnitude_);
    for (std::uint64_t m = groups; m != 0; m &= m - 1) {
      const int g = std::countr_zero(m);
      const std::size_t block = static_cast<std::size_t>(g / 8);
      const int bit = g % 8;
      const bool sides = (sides_[block] >> bit & 1u) != 0, far = (far_[block] >> bit & 1u) != 0;
      std::uint32_t reach = lanes;
      if (sides || far) {
        Mask8 cut = Mask8::from_bits(0);
        const auto d = [&](int i) { return x.nearest(n_[i][0][g], n_[i][1][g], n_[i][2][g]); };
        if (sides) {
          for (int i = 0; i < 4; ++i) cut = cut | (d(i) > Float8(scale_[i][g]) * x.margin + Float8(offset_[i][g]));
        }
        if (far) cut = cut | (d(4) > Float8(scale_[4][g]) * x.margin + Float8(offset_[4][g]));
        reach &= ~cut.bits();
      }
      for (; reach != 0; reach &= reach - 1) out[std::countr_zero(reach)] |= std::uint64_t{1} << g;
    }
  }

  // Whether any group or the packet has a plane to cull with.
  bool any_plane() const {
    if (bound_groups_ != 0) return true;
    for (std::size_t b = 0; b < sides_.size(); ++b) {
      if ((sides_[b] | far_[b]) != 0) return true;
    }
    return false;
  }

  // Whether reached() tests triangles against the groups' slabs in the
  // packet's basis (set_bound) rather than their own frusta.
  void use_slabs(bool on) { slabs_on_ = on; }
  // The groups set_bound gave slabs.
  std::uint64_t slab_groups() const { return slab_groups_; }

 private:
  // A shape (nearest: its least signed distance to eight planes) against
  // the packet's frustum first, its planes side by side with uncut()'s test
  // and margin, then the groups' slabs (slabs()) or their own frusta.
  template <class Nearest, class Slabs>
  std::uint64_t packet_then_groups(std::uint64_t groups, float corners, Nearest&& nearest, Slabs&& slabs) const {
    if (groups != 0 && (groups & ~bound_groups_) == 0) {
      const Float8 d = nearest(Float8::load(bound_n_[0]), Float8::load(bound_n_[1]), Float8::load(bound_n_[2]));
      const Float8 limit =
          Float8::load(bound_scale_) * cull_margin(corners, apex_magnitude_) + Float8::load(bound_offset_);
      if ((d > limit).bits() != 0) return 0;
      if (slabs_on_ && (groups & ~slab_groups_) == 0) return slabs();
    }
    return uncut(groups, corners, nearest);
  }

  // The groups of `groups` whose slab in the packet's basis (c, u, v) no
  // side cuts off: a side plane u - s c has distance u.x - s (c.x) from a
  // point x (relative to the apex), so the three corners' coordinates in
  // the basis are taken once per triangle and each block of eight groups
  // costs a product and a difference per corner and side, where its own
  // frusta cost a dot product (traverse/large_packet.h, shadow packets).
  std::uint64_t slabs_uncut(std::uint64_t groups, float corners, const Vec3& x0, const Vec3& x1,
                            const Vec3& x2) const {
    const Vec3& c = slab_basis_[0];
    const Vec3& u = slab_basis_[1];
    const Vec3& v = slab_basis_[2];
    const Float8 z0(dot3(c, x0)), z1(dot3(c, x1)), z2(dot3(c, x2));
    const Float8 a0(dot3(u, x0)), a1(dot3(u, x1)), a2(dot3(u, x2));
    const Float8 b0(dot3(v, x0)), b1(dot3(v, x1)), b2(dot3(v, x2));
    const Float8 z_min = min(min(z0, z1), z2);
    return slabs_uncut_by(groups, corners, z_min, [&](Float8 a_lo, Float8 a_hi, Float8 b_lo, Float8 b_hi) {
      // Beyond the high side: every corner's u.x - a_hi (c.x) past the margin.
      return SlabDistances{min(min(a0 - a_hi * z0, a1 - a_hi * z1), a2 - a_hi * z2),
                           min(min(a_lo * z0 - a0, a_lo * z1 - a1), a_lo * z2 - a2),
                           min(min(b0 - b_hi * z0, b1 - b_hi * z1), b2 - b_hi * z2),
                           min(min(b_lo * z0 - b0, b_lo * z1 - b1), b_lo * z2 - b2)};
    });
  }
  // slabs_uncut for the box [lo, hi] (relative to the apex): each side's
  // u.x - s (c.x) is at least u.x's least over the box minus s times c.x's
  // greatest (least, for s < 0) over it, each the sum dot3 takes at a point
  // with the nearer corner's products, so the box's bound never exceeds a
  // point's (rounding is monotone). Looser than the box's own nearest
  // corner by about |s| times its depth, which is small beside a pixel for
  // the boxes this sees (a leaf's, an object's).
  std::uint64_t slabs_box_uncut(std::uint64_t groups, float corners, const Vec3& lo, const Vec3& hi) const {
    const Vec3& c = slab_basis_[0];
    const Vec3& u = slab_basis_[1];
    const Vec3& v = slab_basis_[2];
    const auto least = [&](const Vec3& w) {
      return (std::min(w.x * lo.x, w.x * hi.x) + std::min(w.y * lo.y, w.y * hi.y)) + std::min(w.z * lo.z, w.z * hi.z);
    };
    const auto most = [&](const Vec3& w) {
      return (std::max(w.x * lo.x, w.x * hi.x) + std::max(w.y * lo.y, w.y * hi.y)) + std::max(w.z * lo.z, w.z * hi.z);
    };
    const Float8 a_least(least(u)), a_most(most(u)), b_least(least(v)), b_most(most(v));
    const Float8 z_least(least(c)), z_most(most(c));
    const Float8 zero(0.0f);
    // s (c.x) at its greatest: c.x's greatest for s >= 0, its least below.
    const auto s_z_most = [&](Float8 s) { return s * select(s >= zero, z_most, z_least); };
    const auto s_z_least = [&](Float8 s) { return s * select(s >= zero, z_least, z_most); };
    return slabs_uncut_by(groups, corners, z_least, [&](Float8 a_lo, Float8 a_hi, Float8 b_lo, Float8 b_hi) {
      return SlabDistances{a_least - s_z_most(a_hi), s_z_least(a_lo) - a_most, b_least - s_z_most(b_hi),
                           s_z_least(b_lo) - b_most};
    });
  }
  // A shape's least distances past eight groups' slab sides: u high, u
  // low, v high, v low.
  struct SlabDistances {
    Float8 a_hi, a_lo, b_hi, b_lo;
  };
  // The groups of `groups`, eight at a time, that no side of their slab
  // cuts off: distances(a_lo, a_hi, b_lo, b_hi) gives the shape's distances
  // past the sides of eight groups' slopes, z_min its least depth along c
  // (for the far plane); each must exceed the margin to cut.
  template <class Distances>
  std::uint64_t slabs_uncut_by(std::uint64_t groups, float corners, Float8 z_min, Distances&& distances) const {
    const Float8 margin = cull_margin(corners, apex_magnitude_);
    std::uint64_t out = 0;
    for (int base = 0; base < groups_; base += 8) {
      const std::uint64_t part = (groups >> base) & 0xFFu;
      if (part == 0) continue;
      const SlabDistances d = distances(Float8::load(&slab_[0][base]), Float8::load(&slab_[1][base]),
                                        Float8::load(&slab_[2][base]), Float8::load(&slab_[3][base]));
      const auto beyond = [&](Float8 distance, int i) {
        return distance > Float8::load(&slab_scale_[i][base]) * margin + Float8::load(&slab_offset_[i][base]);
      };
      const Mask8 cut = beyond(d.a_hi, 1) | beyond(d.a_lo, 0) | beyond(d.b_hi, 3) | beyond(d.b_lo, 2) |
                        (z_min > Float8::load(&slab_far_[base]) + Float8(slab_far_scale_) * margin);
      out |= (part & ~static_cast<std::uint64_t>(cut.bits())) << base;
    }
    return out;
  }
  // A dot product summed as (x + y) + z, the order slabs_box_uncut bounds.
  static float dot3(const Vec3& a, const Vec3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
  static float l1(const Vec3& w) { return std::fabs(w.x) + std::fabs(w.y) + std::fabs(w.z); }

  // The groups of `groups` that no plane of theirs cuts off, eight at a
  // time: nearest(nx, ny, nz) is the shape's least signed distance
  // n . (p - apex) to each group's plane n, and a plane cuts the shape off
  // when that exceeds the margin for coordinates up to `corners` (for the
  // far plane, beyond its offset). Groups without a frustum are never cut.
  template <class Nearest>
  std::uint64_t uncut(std::uint64_t groups, float corners, Nearest&& nearest) const {
    const Float8 margin = cull_margin(corners, apex_magnitude_);
    std::uint64_t out = 0;
    for (int base = 0; base < groups_; base += 8) {
      const std::uint64_t part = (groups >> base) & 0xFFu;
      if (part == 0) continue;
      const std::uint32_t block = static_cast<std::uint32_t>(base / 8);
      const std::uint32_t sides = sides_[block], far = far_[block];
      if ((part & (sides | far)) == 0) {
        out |= part << base;  // no group here has a frustum
        continue;
      }
      Mask8 culled_by_sides = Mask8::from_bits(0), culled_by_far = Mask8::from_bits(0);
      for (int i = 0; i < (far != 0 ? 5 : 4); ++i) {
        const Float8 d = nearest(Float8::load(&n_[i][0][base]), Float8::load(&n_[i][1][base]),
                                 Float8::load(&n_[i][2][base]));
        const Float8 limit = Float8::load(&scale_[i][base]) * margin + Float8::load(&offset_[i][base]);
        if (i == 4) {
          culled_by_far = d > limit;
        } else {
          culled_by_sides = culled_by_sides | (d > limit);
        }
      }
      const std::uint64_t culled = (culled_by_sides.bits() & sides) | (culled_by_far.bits() & far);
      out |= (part & ~culled) << base;
    }
    return out;
  }

  // The frusta of groups base + k for the bits k of `block`, lane k of
  // every vector below holding group base + k. A group's lanes not in
  // lanes(g) repeat its first live lane, so they widen nothing.
  template <bool kFar, class Q, class Lanes, class Reach>
  void set_block(int base, std::uint32_t block, float sign, Q& q, Lanes& lanes, Reach& reach) {
    if (!kFar && apex_radius_ > 0.0f) return;  // segments need their ends
    alignas(32) float t[3][8][8];    // [axis][ray][group]
    alignas(32) float r[8][8] = {};  // [ray][group]
    std::uint32_t full = 0;          // the groups with live lanes
    for (int k = 0; k < 8; ++k) {
      const std::uint32_t l = (block >> k & 1u) != 0 ? lanes(base + k) & 0xFFu : 0u;
      if (l != 0) full |= 1u << k;
      const int first = l != 0 ? std::countr_zero(l) : 0;
      alignas(32) float rk[8] = {};
      if constexpr (kFar) {
        if (l != 0) reach(base + k, rk);
      }
      for (int j = 0; j < 8; ++j) {
        const int lane = (l >> j & 1u) != 0 ? j : first;
        for (int a = 0; a < 3; ++a) t[a][j][k] = l != 0 ? sign * q(base + k)[a][lane] : (a == 2 ? 1.0f : 0.0f);
        r[j][k] = rk[lane];
      }
    }
    const Float8 zero(0.0f), one(1.0f);
    Vec3x8 d[8];
    for (int j = 0; j < 8; ++j) d[j] = Vec3x8{Float8::load(t[0][j]), Float8::load(t[1][j]), Float8::load(t[2][j])};
    const auto unit = [&](const Vec3x8& w, Mask8& ok) {
      const Float8 length = sqrt(dot(w, w));
      ok = (length > zero) & is_finite(length);
      return (one / select(ok, length, one)) * w;
    };
    Vec3x8 sum = d[0];
    for (int j = 1; j < 8; ++j) sum = sum + d[j];
    Mask8 c_ok, u_ok, alt_ok;
    const Vec3x8 c = unit(sum, c_ok);
    // u along a pixel row (a camera block's lanes are two rows of four): any
    // u bounds the rays, one along the rows bounds a block most tightly.
    Vec3x8 across = d[3] - d[0];
    across = across - dot(across, c) * c;
    const Vec3x8 u_across = unit(across, u_ok);
    const Vec3x8 alt = select(abs(c.x) < Float8(0.5f), Vec3x8{zero, zero - c.z, c.y}, Vec3x8{zero - c.z, zero, c.x});
    const Vec3x8 u = select(u_ok, u_across, unit(alt, alt_ok));
    const Vec3x8 v = cross(c, u);
    Mask8 ok = c_ok & (u_ok | alt_ok) & Mask8::from_bits(full);
    Float8 dc[8];
    for (int j = 0; j < 8; ++j) {
      dc[j] = dot(d[j], c);
      const Float8 dd = dot(d[j], d[j]);
      ok = ok & (dc[j] > zero) & (dc[j] * dc[j] > Float8(0.0625f) * dd) & is_finite(dd);
    }
    if (ok.bits() == 0) return;
    const float big = std::numeric_limits<float>::max();
    Float8 a_lo(big), a_hi(-big), b_lo(big), b_hi(-big), far(0.0f);
    for (int j = 0; j < 8; ++j) {
      const Float8 inv_dc = one / select(ok, dc[j], one);
      const Float8 a = dot(d[j], u) * inv_dc, b = dot(d[j], v) * inv_dc;
      a_lo = min(a_lo, a);
      a_hi = max(a_hi, a);
      b_lo = min(b_lo, b);
      b_hi = max(b_hi, b);
      if constexpr (kFar) far = max(far, Float8::load(r[j]) * dc[j]);
    }
    const Float8 far_reach = far_offset(far);
    const Vec3x8 planes[4] = {u - (a_hi + grown_slope(a_hi)) * c, (a_lo - grown_slope(a_lo)) * c - u,
                              v - (b_hi + grown_slope(b_hi)) * c, (b_lo - grown_slope(b_lo)) * c - v};
    if (apex_radius_ > 0.0f) {
      // Segments from within the radius: only groups whose ends lie well
      // beyond it, each side tilted to hold them.
      ok = ok & (far_reach > Float8(2.0f * apex_radius_)) & is_finite(far_reach);
      if (ok.bits() == 0) return;
      for (int i = 0; i < 4; ++i) {
        const TiltedSide side = tilt_side(planes[i], c, far_reach, apex_radius_);
        store_planes(i, base, side.n, side.offset, ok);
      }
    } else {
      for (int i = 0; i < 4; ++i) store_planes(i, base, planes[i], zero, ok);
    }
    sides_[static_cast<std::size_t>(base / 8)] |= static_cast<std::uint8_t>(ok.bits());
    if constexpr (kFar) {
      const Mask8 far_ok = ok & is_finite(far_reach);
      if (far_ok.bits() != 0) {
        store_planes(4, base, c, far_reach, far_ok);
        far_[static_cast<std::size_t>(base / 8)] |= static_cast<std::uint8_t>(far_ok.bits());
      }
    }
  }
  // Plane i of the groups base + k for the lanes k of `m`: its normal, its
  // |n|_1 (slightly more, for the rounding of the products) and its offset.
  void store_planes(int i, int base, const Vec3x8& n, Float8 offset, Mask8 m) {
    const Float8* const axis[3] = {&n.x, &n.y, &n.z};
    for (int a = 0; a < 3; ++a) select(m, *axis[a], Float8::load(&n_[i][a][base])).store(&n_[i][a][base]);
    const Float8 scale = Float8(1.001f) * ((abs(n.x) + abs(n.y)) + abs(n.z));
    select(m, scale, Float8::load(&scale_[i][base])).store(&scale_[i][base]);
    select(m, offset, Float8::load(&offset_[i][base])).store(&offset_[i][base]);
  }

  std::uint64_t live_groups() const { return groups_ >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << groups_) - 1u; }
  static float magnitude(const Vec3& p) { return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}); }
  // Near unit length is enough: the planes hold the rays for any centre
  // and any u, so one reciprocal serves the three axes.
  static Vec3 normalized(const Vec3& w) {
    const float length = std::sqrt(glm::dot(w, w));
    return length > 0.0f && std::isfinite(length) ? w * (1.0f / length)
                                                  : Vec3(std::numeric_limits<float>::quiet_NaN());
  }
  // The frame a frustum's slopes are measured in around the unit centre
  // c: u along `across` (a pixel row) made perpendicular to c, or any
  // perpendicular where that is degenerate, and v = c x u.
  static bool row_basis(const Vec3& c, Vec3 across, Vec3& u, Vec3& v) {
    across = across - glm::dot(across, c) * c;
    u = normalized(across);
    if (!(u.x == u.x)) u = normalized(std::fabs(c.x) < 0.5f ? Vec3(0.0f, -c.z, c.y) : Vec3(-c.z, 0.0f, c.x));
    if (!(u.x == u.x)) return false;
    v = glm::cross(c, u);
    return true;
  }
  // Each lane's slopes a = d.u / d.c and b = d.v / d.c (and d.c) over the
  // lanes of `use`; false unless every such lane lies well in front of the
  // centre (within about 75 degrees of it: slopes stay finite and small;
  // non-finite lanes fail too).
  static bool slopes(const Vec3x8& d, Mask8 use, const Vec3& c, const Vec3& u, const Vec3& v, Float8& a, Float8& b,
                     Float8& dc) {
    const auto along = [&](const Vec3& w) { return d.x * Float8(w.x) + d.y * Float8(w.y) + d.z * Float8(w.z); };
    dc = along(c);
    const Float8 zero(0.0f);
    const Mask8 in_front = (dc > zero) & (dc * dc > Float8(0.0625f) * dot(d, d)) & is_finite(dot(d, d));
    if ((in_front | !use).bits() != 0xFFu) return false;
    const Float8 inv_dc = Float8(1.0f) / select(use, dc, Float8(1.0f));
    a = along(u) * inv_dc;
    b = along(v) * inv_dc;
    return true;
  }
  Vec3 apex_{0.0f};
  float apex_radius_ = 0.0f;  // reset(): the segments start within it of the apex
  float apex_magnitude_ = 0.0f;
  int groups_ = 0;
  // Per plane (four sides, then the far plane), axis and group; read only
  // for the groups whose bit is set in sides_ (the four sides) or far_ (the
  // far plane), per block of eight groups.
  alignas(32) std::array<std::array<std::array<float, kMaxGroups>, 3>, 5> n_{};
  std::array<std::uint8_t, kMaxGroups / 8> sides_{}, far_{};
  alignas(32) std::array<std::array<float, kMaxGroups>, 5> scale_{};
  alignas(32) std::array<std::array<float, kMaxGroups>, 5> offset_{};  // per plane and group
  // The packet's frustum (set_bound): lane i of each array is plane i (four
  // sides, then the far plane), for the groups of bound_groups_.
  alignas(32) float bound_n_[3][8] = {};
  alignas(32) float bound_scale_[8] = {};
  alignas(32) float bound_offset_[8] = {};
  std::uint64_t bound_groups_ = 0;
  // Per group its slab in the packet's basis (set_bound): slopes along u
  // (lo, hi) and v (lo, hi) grown as the planes', each side's |n|_1, and the
  // far offset along c (max float: none).
  bool slabs_on_ = false;
  std::uint64_t slab_groups_ = 0;
  Vec3 slab_basis_[3] = {Vec3(0.0f), Vec3(0.0f), Vec3(0.0f)};  // c, u, v
  alignas(32) std::array<std::array<float, kMaxGroups>, 4> slab_{};
  alignas(32) std::array<std::array<float, kMaxGroups>, 4> slab_scale_{};
  alignas(32) std::array<std::array<float, kMaxGroups>, 4> slab_offset_{};  // tilted sides' (tilt_side)
  alignas(32) std::array<float, kMaxGroups> slab_far_{};
  float slab_far_scale_ = 0.0f;
};

}  // namespace sinew::rt
