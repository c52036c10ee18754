// The per-ray pieces every traversal width shares, written once over a lane
// type: F is float for one ray (traverse/traversal.cpp) or Float8 for eight
// lanes (traverse/packet_traversal.cpp, traverse/large_packet.cpp). Each
// function below is the single ray's arithmetic, operation for operation,
// so a lane of a packet reaches exactly the cells its single ray reaches:
//
//   valid_rays        the rays the queries accept
//   world_slack       the slack a world-space box is grown by
//   to_bone_frame     a world ray carried into a bone's frame, with the slack
//                     of that frame (the escape tolerance and the rounding of
//                     both frame changes)
//   clip_to_box       [t0, t1] clipped to a box grown by each lane's slack
//
// The scalar lane operations below take the eight-lane instructions'
// semantics (a NaN operand picks the second), which are also the
// std::min / std::max the single ray was written with, argument order
// reversed: min(x, t1) == std::min(t1, x), NaN included.
#pragma once

#include <cmath>
#include <limits>

#include "raytrace/scene/frame_state.h"
#include "runtime/math/aabb.h"
#include "runtime/math/affine.h"
#include "runtime/math/float8.h"
#include "runtime/math/types.h"

namespace sinew::rt::per_lane {

inline float min(float a, float b) { return a < b ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline float abs(float a) { return std::fabs(a); }
inline float select(bool mask, float yes, float no) { return mask ? yes : no; }
// Lane-wise and: `&` on masks, `&&` on one lane's bool.
inline bool both(bool a, bool b) { return a && b; }
inline Mask8 both(Mask8 a, Mask8 b) { return a & b; }
using sinew::abs;
using sinew::max;
using sinew::min;
using sinew::select;

// The vector and mask of a lane type.
template <class F>
struct LaneTypes;
template <>
struct LaneTypes<float> {
  using Vec = Vec3;
  using Mask = bool;
};
template <>
struct LaneTypes<Float8> {
  using Vec = Vec3x8;
  using Mask = Mask8;
};
template <class F>
using LaneVec = typename LaneTypes<F>::Vec;
template <class F>
using LaneMask = typename LaneTypes<F>::Mask;

// Every lane.
template <class F>
LaneMask<F> all_lanes();
template <>
inline bool all_lanes<float>() {
  return true;
}
template <>
inline Mask8 all_lanes<Float8>() {
  return Mask8::from_bits(0xFFu);
}

template <class F>
[[gnu::always_inline]] inline F max_abs(const LaneVec<F>& v) {
  return max(max(abs(v.x), abs(v.y)), abs(v.z));
}

// Rays the queries accept: finite origin and direction, a non-zero
// direction, t_min < t_max (false for NaN).
template <class F>
[[gnu::always_inline]] inline LaneMask<F> valid_rays(const LaneVec<F>& o, const LaneVec<F>& d, F t_min, F t_max) {
  const F big(std::numeric_limits<float>::max());
  const auto finite = [&](F x) { return abs(x) <= big; };
  const LaneMask<F> all_finite = both(both(both(finite(o.x), finite(o.y)), both(finite(o.z), finite(d.x))),
                                      both(finite(d.y), finite(d.z)));
  const LaneMask<F> zero = both(both(d.x == F(0.0f), d.y == F(0.0f)), d.z == F(0.0f));
  return both(both(t_min < t_max, all_finite), !zero);
}

// The slack of a world-space computation for a box of magnitude
// `box_magnitude` (max_abs of its corners) reached up to t_end: rounding
// relative to the ray's origin (o_mag), its reach (t_end d_mag; 0 for an
// infinite t_end) and the box's own coordinates.
template <class F>
[[gnu::always_inline]] inline F world_slack(F o_mag, F d_mag, float box_magnitude, F t_end) {
  const F reach = select(abs(t_end) <= F(std::numeric_limits<float>::max()), t_end * d_mag, F(0.0f));
  return F(kFrameRelativeSlack) * ((o_mag + reach) + F(box_magnitude));
}

// A ray in the frame of the tree being walked, with its slack there.
template <class F>
struct FrameRay {
  LaneVec<F> o, d;
  F eps;
};

// The world ray (wo + t wd, origin magnitude world_o_mag) in bone `bone`'s
// frame of `frame`, term by term as Affine3::transform_point and
// transform_vector, so t is the same in both frames (lanes outside `use`
// get o = 0 and d = 1, which keep the arithmetic finite); and its slack there
// over [.., t1]: the escape check's tolerance (a vertex may sit that far
// outside its box and still count as inside), twice, for the rounding of
// both frame changes, plus the rounding of carrying this ray over and of
// the traversal arithmetic:
//   2 tolerance + slack (((carried + |o|) + t1 |d|) + |bounds|),
//   carried = linear_norm |world origin| + translation magnitude.
template <class F>
[[gnu::always_inline]] inline FrameRay<F> to_bone_frame(const InstanceFrame& frame, std::uint32_t bone, const LaneVec<F>& wo,
                          const LaneVec<F>& wd, F world_o_mag, F t1, LaneMask<F> use = all_lanes<F>()) {
  const Affine3& m = frame.bone_from_world[bone];
  const InstanceFrame::BoneCarry& carry = frame.bone_carry[bone];
  const auto point = [&](const Vec4& r) { return ((F(r.x) * wo.x + F(r.y) * wo.y) + F(r.z) * wo.z) + F(r.w); };
  const auto vector = [&](const Vec4& r) { return (F(r.x) * wd.x + F(r.y) * wd.y) + F(r.z) * wd.z; };
  FrameRay<F> r;
  const F zero(0.0f), one(1.0f);
  r.o = {select(use, point(m.rows[0]), zero), select(use, point(m.rows[1]), zero), select(use, point(m.rows[2]), zero)};
  r.d = {select(use, vector(m.rows[0]), one), select(use, vector(m.rows[1]), one), select(use, vector(m.rows[2]), one)};
  const F carried = F(carry.linear_norm) * world_o_mag + F(carry.translation_magnitude);
  r.eps = F(2.0f * frame.tolerance[bone]) +
          F(kFrameRelativeSlack) * (((carried + max_abs<F>(r.o)) + t1 * max_abs<F>(r.d)) + F(carry.bounds_magnitude));
  return r;
}

// 1 / d per axis, correctly rounded.
template <class F>
[[gnu::always_inline]] inline LaneVec<F> reciprocal(const LaneVec<F>& d) {
  return {F(1.0f) / d.x, F(1.0f) / d.y, F(1.0f) / d.z};
}

// Clips each lane's [t0, t1] to its ray's passage through `box` grown by
// its eps on every side; returns the lanes left with t0 <= t1 (a ray
// parallel to an axis is kept on that axis only when its origin lies within
// the grown slab). The growth absorbs the rounding of the slab arithmetic,
// which is relative to the magnitudes the callers fold into eps.
template <class F>
[[gnu::always_inline]] inline LaneMask<F> clip_to_box(const Aabb& box, F eps, const LaneVec<F>& o, const LaneVec<F>& d, const LaneVec<F>& inv,
                        F& t0, F& t1) {
  const F* const oc[3] = {&o.x, &o.y, &o.z};
  const F* const dc[3] = {&d.x, &d.y, &d.z};
  const F* const ic[3] = {&inv.x, &inv.y, &inv.z};
  LaneMask<F> inside = all_lanes<F>();
  for (int a = 0; a < 3; ++a) {
    const F lo = F(box.lower[a]) - eps;
    const F hi = F(box.upper[a]) + eps;
    const LaneMask<F> parallel = *dc[a] == F(0.0f);
    inside = both(inside, !both(parallel, !both(*oc[a] >= lo, *oc[a] <= hi)));
    const F n = (lo - *oc[a]) * *ic[a];
    const F f = (hi - *oc[a]) * *ic[a];
    const LaneMask<F> swap = n > f;
    t0 = select(parallel, t0, max(select(swap, f, n), t0));
    t1 = select(parallel, t1, min(select(swap, n, f), t1));
  }
  return both(inside, t0 <= t1);
}

}  // namespace sinew::rt::per_lane
