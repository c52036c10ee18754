// IntervalBound: interval arithmetic over a set of rays, kept as ranges per
// axis (origins, directions) and of the parameter. A ray inside a box at t has
// entry_a <= t <= exit_a on every axis whose direction sign is the same for
// the whole set, and interval products bound those over every ray: one box
// test costs a dozen multiplies whatever the set's size. entry() is a lower
// bound on where the first ray enters a box (+inf: none can), the walks'
// front-to-back key. A large packet builds one over its rays, a tile over
// all of its rays (cull/ray_bound.h). Margins: docs/RAYTRACE.md, "Numerical
// margins" (kBoundRelativeMargin); a set holding a non-finite ray culls
// nothing.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "runtime/math/aabb.h"
#include "runtime/math/float4.h"
#include "runtime/math/float8.h"

namespace sinew::rt {

// The relative widening of every interval product and reciprocal bound
// (2^-20, far above their 2^-24 rounding), shared by IntervalBound and the
// tile bounds of cull/ray_bound.h.
inline constexpr float kBoundRelativeMargin = 0x1.0p-20f;
// Directions smaller than this on an axis give no reciprocal bound there
// (1/d may overflow): such an axis simply does not cull.
inline constexpr float kTinyDirection = 1e-30f;

// A ray set's passage through a box from its per-axis slab entries and exits
// (lane 3 unused: -inf and +inf): [max(t_lo, latest entry), min(t_hi,
// earliest exit)], empty when enter > leave.
struct SlabPassage {
  float enter, leave;
};
inline SlabPassage slab_passage(Float4 enter, Float4 leave, float t_lo, float t_hi) {
  return {std::max(t_lo, reduce_max(enter)), std::min(t_hi, reduce_min(leave))};
}

// A ray set per axis as its box tests read it: x, y and z in lanes 0 to 2,
// lane 3 bounding nothing. Built from the set's origin and direction
// ranges; IntervalBound's arithmetic.
struct AxisRanges {
  Float4 o_lo{0.0f}, o_hi{0.0f};  // origins
  // Reciprocal directions where every direction has one sign (1/d
  // decreases on each sign, so [1/d_hi, 1/d_lo]), widened; 0 elsewhere.
  Float4 r_lo{0.0f}, r_hi{0.0f};
  Mask4 positive{}, negative{};       // every direction >= kTinyDirection (<= -kTinyDirection)
  Mask4 not_rising{}, not_falling{};  // no direction > 0 (< 0)
  Float4 d_lo{0.0f}, d_hi{0.0f};      // the directions (the swept box of passage)
  // A box holding every point of every ray over its parameter range, where
  // the set knows one (RayRanges::p_lo, p_hi); +-inf elsewhere.
  Float4 p_lo{-std::numeric_limits<float>::infinity()}, p_hi{std::numeric_limits<float>::infinity()};

  static AxisRanges from(const float (&o_lo)[3], const float (&o_hi)[3], const float (&d_lo)[3],
                         const float (&d_hi)[3], const float (&p_lo)[3], const float (&p_hi)[3]) {
    const float ones = std::bit_cast<float>(0xFFFFFFFFu);
    float olo[4], ohi[4], rlo[4], rhi[4], pos[4], neg[4], nr[4], nf[4];
    for (int a = 0; a < 4; ++a) {
      const bool axis = a < 3;
      olo[a] = axis ? o_lo[a] : 0.0f;
      ohi[a] = axis ? o_hi[a] : 0.0f;
      const bool rising = axis && d_lo[a] >= kTinyDirection;
      const bool falling = axis && d_hi[a] <= -kTinyDirection;
      pos[a] = rising ? ones : 0.0f;
      neg[a] = falling ? ones : 0.0f;
      nr[a] = axis && d_hi[a] <= 0.0f ? ones : 0.0f;
      nf[a] = axis && d_lo[a] >= 0.0f ? ones : 0.0f;
      const float lo = rising || falling ? 1.0f / d_hi[a] : 0.0f;
      const float hi = rising || falling ? 1.0f / d_lo[a] : 0.0f;
      rlo[a] = lo - std::fabs(lo) * kBoundRelativeMargin;
      rhi[a] = hi + std::fabs(hi) * kBoundRelativeMargin;
    }
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const float dlo[4] = {d_lo[0], d_lo[1], d_lo[2], 0.0f}, dhi[4] = {d_hi[0], d_hi[1], d_hi[2], 0.0f};
    const float plo[4] = {p_lo[0], p_lo[1], p_lo[2], -kInf}, phi[4] = {p_hi[0], p_hi[1], p_hi[2], kInf};
    return {Float4::load(olo), Float4::load(ohi), Float4::load(rlo), Float4::load(rhi),
            Mask4::load(pos),  Mask4::load(neg),  Mask4::load(nr),   Mask4::load(nf),
            Float4::load(dlo), Float4::load(dhi), Float4::load(plo), Float4::load(phi)};
  }

  // The set's passage through the box [lo, hi] (grown by the caller) within
  // [t_lo, t_hi]; empty (enter > leave) when no ray of the set can enter it.
  SlabPassage passage(Float4 lo, Float4 hi, float t_lo, float t_hi) const {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    // Every origin on one side of a slab, no direction turning towards it.
    if (((o_hi < lo) & not_rising).any() || ((o_lo > hi) & not_falling).any()) return {kInf, -kInf};
    // Over a bounded parameter range, the box the rays sweep: on every axis
    // o + t d lies between o_lo and o_hi moved by the extremes of t d (the
    // corners of [t_lo, t_hi] x [d_lo, d_hi]), and within the set's own
    // box of points where it has one (the segments' starts and ends, which
    // keeps what the ranges of o and d lose: segments from an area light
    // that all end above a floor), widened by the rounding of o + t d. It
    // bounds the axes the slabs below cannot (directions of both signs): a
    // segment set (ambient occlusion, an area light's samples) reaches
    // only boxes near it.
    if (t_hi < kInf && t_lo > -kInf) {
      const Float4 tl(t_lo), th(t_hi);
      const Float4 reach_lo = min(min(tl * d_lo, th * d_lo), min(tl * d_hi, th * d_hi));
      const Float4 reach_hi = max(max(tl * d_lo, th * d_lo), max(tl * d_hi, th * d_hi));
      const Float4 slop =
          Float4(kBoundRelativeMargin) * (max(abs(o_lo), abs(o_hi)) + max(abs(reach_lo), abs(reach_hi)));
      const Float4 swept_lo = max(o_lo + reach_lo, p_lo) - slop;
      const Float4 swept_hi = min(o_hi + reach_hi, p_hi) + slop;
      if (((swept_hi < lo) | (swept_lo > hi)).any()) return {kInf, -kInf};
    }
    // Rising rays enter through the lower plane and leave through the
    // upper, falling ones the other way; other axes bound nothing. Each
    // plane's bound is an extreme of the four products of its offset range
    // and the reciprocal range, widened.
    const auto products = [&](Float4 plane, auto extreme) {
      const Float4 a0 = plane - o_hi, a1 = plane - o_lo;
      return extreme(extreme(a0 * r_lo, a0 * r_hi), extreme(a1 * r_lo, a1 * r_hi));
    };
    const Float4 rel(kBoundRelativeMargin);
    const Float4 lower = products(select(positive, lo, hi), [](Float4 a, Float4 b) { return min(a, b); });
    const Float4 upper = products(select(positive, hi, lo), [](Float4 a, Float4 b) { return max(a, b); });
    const Mask4 bounded = positive | negative;
    const Float4 enter = select(bounded, lower - abs(lower) * rel, Float4(-kInf));
    const Float4 leave = select(bounded, upper + abs(upper) * rel, Float4(kInf));
    return slab_passage(enter, leave, t_lo, t_hi);
  }
};

// Ranges of a set of rays: origin and direction per axis, parameter.
struct RayRanges {
  float o_lo[3] = {0, 0, 0}, o_hi[3] = {0, 0, 0};
  float d_lo[3] = {0, 0, 0}, d_hi[3] = {0, 0, 0};
  float t_lo = 0.0f, t_hi = 0.0f;
  // A box holding every point o + t d of every ray over its own [t_min,
  // t_max], where the set keeps one (cull/ray_bound.h RayBound); +-inf:
  // none.
  float p_lo[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                   -std::numeric_limits<float>::infinity()};
  float p_hi[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                   std::numeric_limits<float>::infinity()};
  bool finite = true;

  // The largest |origin| coordinate.
  float origin_magnitude() const {
    float m = 0.0f;
    for (int a = 0; a < 3; ++a) m = std::max({m, std::fabs(o_lo[a]), std::fabs(o_hi[a])});
    return m;
  }
};

// The ranges of many groups of eight rays, kept lane by lane and reduced
// once: adding a group costs a dozen min/max, not a dozen reductions.
class RangeAccumulator {
 public:
  RangeAccumulator() {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
      o_lo_[a] = d_lo_[a] = Float8(kInf);
      o_hi_[a] = d_hi_[a] = Float8(-kInf);
    }
    t_lo_ = Float8(kInf);
    t_hi_ = Float8(-kInf);
  }
  // Rays o + t d, t in [t0, t1], of the lanes in `mask` (t1 may be +inf).
  [[gnu::always_inline]] void add(const Vec3x8& o, const Vec3x8& d, Float8 t0, Float8 t1, std::uint32_t mask) {
    if (mask == 0) return;
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const Mask8 use = Mask8::from_bits(mask);
    const Float8 plus(kInf), minus(-kInf);
    const Float8* const oc[3] = {&o.x, &o.y, &o.z};
    const Float8* const dc[3] = {&d.x, &d.y, &d.z};
    Mask8 finite = is_finite(t0);
    for (int a = 0; a < 3; ++a) {
      o_lo_[a] = min(o_lo_[a], select(use, *oc[a], plus));
      o_hi_[a] = max(o_hi_[a], select(use, *oc[a], minus));
      d_lo_[a] = min(d_lo_[a], select(use, *dc[a], plus));
      d_hi_[a] = max(d_hi_[a], select(use, *dc[a], minus));
      finite = finite & is_finite(*oc[a]) & is_finite(*dc[a]);
    }
    t_lo_ = min(t_lo_, select(use, t0, plus));
    t_hi_ = max(t_hi_, select(use, t1, minus));
    finite_ = finite_ && (finite.bits() & mask) == mask;
    any_ = true;
  }
  bool empty() const { return !any_; }
  RayRanges ranges() const {
    RayRanges r;
    for (int a = 0; a < 3; ++a) {
      r.o_lo[a] = reduce_min(o_lo_[a]);
      r.o_hi[a] = reduce_max(o_hi_[a]);
      r.d_lo[a] = reduce_min(d_lo_[a]);
      r.d_hi[a] = reduce_max(d_hi_[a]);
    }
    r.t_lo = reduce_min(t_lo_);
    r.t_hi = reduce_max(t_hi_);
    r.finite = finite_;
    return r;
  }

 private:
  Float8 o_lo_[3], o_hi_[3], d_lo_[3], d_hi_[3];
  Float8 t_lo_, t_hi_;
  bool finite_ = true;
  bool any_ = false;
};

class IntervalBound {
 public:
  IntervalBound() = default;
  explicit IntervalBound(const RayRanges& r)
      : ranges_(AxisRanges::from(r.o_lo, r.o_hi, r.d_lo, r.d_hi, r.p_lo, r.p_hi)) {
    unbounded_ = !r.finite;
    // A set holding a non-finite ray spans every parameter.
    t_lo_ = unbounded_ ? -std::numeric_limits<float>::infinity() : r.t_lo;
    t_hi_ = unbounded_ ? std::numeric_limits<float>::infinity() : r.t_hi;
    alignas(16) float rlo[4], rhi[4];
    ranges_.r_lo.store(rlo);
    ranges_.r_hi.store(rhi);
    for (int a = 0; a < 3; ++a) {
      axis_[a].o_lo = r.o_lo[a];
      axis_[a].o_hi = r.o_hi[a];
      axis_[a].r_lo = rlo[a];
      axis_[a].r_hi = rhi[a];
      axis_[a].sign = r.d_lo[a] >= kTinyDirection ? 1 : r.d_hi[a] <= -kTinyDirection ? -1 : 0;
    }
  }

  // How much to grow boxes by, per axis.
  struct Growth {
    Float4 v;         // x, y, z, 0
    float axis[3];
  };

  // The growth for boxes inside `enclosing` that absorbs this bound's own
  // rounding, on top of the caller's `slack`: the rounding of
  // (plane - origin) on an axis is relative to that axis's coordinates
  // alone, so a flat ground is not grown at the scale of its width.
  Growth grow_for(const Aabb& enclosing, float slack) const {
    Growth g;
    alignas(16) float v[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int a = 0; a < 3; ++a) {
      const float box = std::max(std::fabs(enclosing.lower[a]), std::fabs(enclosing.upper[a]));
      const float origin = std::max(std::fabs(axis_[a].o_lo), std::fabs(axis_[a].o_hi));
      // NaN coordinates make the growth NaN, and so every box test pass.
      const float m = box != box || origin != origin ? box + origin : std::max(box, origin);
      v[a] = g.axis[a] = slack + kBoundRelativeMargin * m;
    }
    g.v = Float4::load(v);
    return g;
  }

  float t_lo() const { return t_lo_; }
  float t_hi() const { return t_hi_; }

  // Whether some ray of the set may pass through `box` grown by `slack`
  // plus grow_for's margin for that box alone; false only when none can.
  // A box with a NaN is never culled.
  bool may_enter(const Aabb& box, float slack) const {
    if (unbounded_) return true;
    const Float4 lower(box.lower, 0.0f), upper(box.upper, 0.0f);
    if (unordered(lower, upper).any()) return true;
    const Float4 mag = max(max(abs(lower), abs(upper)), max(abs(ranges_.o_lo), abs(ranges_.o_hi)));
    const Float4 margin = Float4(slack) + Float4(kBoundRelativeMargin) * mag;
    const SlabPassage p = ranges_.passage(lower - margin, upper + margin, t_lo_, t_hi_);
    return !(p.enter > p.leave);
  }

  // A lower bound on the parameter, within [t_lo, t_hi], at which some ray
  // enters `box` grown by `grow` on every side; +inf when no ray does.
  float entry(const Aabb& box, const Growth& grow, float t_hi) const {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    if (unbounded_) return -kInf;
    const SlabPassage p = ranges_.passage(Float4(box.lower, 0.0f) - grow.v, Float4(box.upper, 0.0f) + grow.v, t_lo_, t_hi);
    return p.enter <= p.leave ? p.enter : kInf;
  }
  float entry(const Aabb& box, const Growth& grow) const { return entry(box, grow, t_hi_); }

  // The direction sign of every ray of the set on axis a: +1, -1, or 0
  // (mixed, zero or too small to bound).
  int sign(int a) const { return axis_[a].sign; }

  // For an axis of fixed sign: bounds on the parameter at which the rays
  // cross the plane x_a = plane, over every ray of the set (the plane
  // offset by the caller's growth).
  float crossing_lo(int a, float plane) const {
    const Axis& x = axis_[a];
    const float a0 = plane - x.o_hi, a1 = plane - x.o_lo;
    const float mn = std::min(std::min(a0 * x.r_lo, a0 * x.r_hi), std::min(a1 * x.r_lo, a1 * x.r_hi));
    return mn - std::fabs(mn) * kBoundRelativeMargin;
  }
  float crossing_hi(int a, float plane) const {
    const Axis& x = axis_[a];
    const float a0 = plane - x.o_hi, a1 = plane - x.o_lo;
    const float mx = std::max(std::max(a0 * x.r_lo, a0 * x.r_hi), std::max(a1 * x.r_lo, a1 * x.r_hi));
    return mx + std::fabs(mx) * kBoundRelativeMargin;
  }

 private:
  AxisRanges ranges_;
  struct Axis {
    float o_lo = 0.0f, o_hi = 0.0f, r_lo = 0.0f, r_hi = 0.0f;
    int sign = 0;
  };
  Axis axis_[3];
  float t_lo_ = 0.0f, t_hi_ = 0.0f;
  bool unbounded_ = false;
};

}  // namespace sinew::rt
