// The packet core's per-group state (traverse/large_packet.cpp): a group's
// eight rays in world space, its part in one object visit, and the
// per-lane pieces of traverse/ray_frames.h bound to a group. Private to
// traverse/.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

#include "raytrace/traverse/ray_frames.h"
#include "runtime/math/aabb.h"
#include "runtime/math/float8.h"

namespace sinew::rt::packet_lanes {

inline constexpr float kInf = std::numeric_limits<float>::infinity();
inline constexpr int kLanes = 8;

template <class Mask, class Fn>
inline void for_each_bit(Mask mask, Fn&& fn) {
  while (mask != 0) {
    const int i = std::countr_zero(mask);
    mask &= mask - 1;
    fn(i);
  }
}

// One group's rays in world space (invalid or inactive lanes hold the
// default Ray, so eight-wide arithmetic stays finite).
struct alignas(32) Group {
  float o[3][kLanes];
  float d[3][kLanes];
  float inv[3][kLanes];
  float t_min[kLanes];
  float t_limit[kLanes];  // closest hit: the best t so far (exclusive); any-hit: t_max
  float o_mag[kLanes];    // max |origin| coordinate
  float d_mag[kLanes];    // max |direction| coordinate
  Vec3x8 origin() const { return {Float8::load(o[0]), Float8::load(o[1]), Float8::load(o[2])}; }
  Vec3x8 direction() const { return {Float8::load(d[0]), Float8::load(d[1]), Float8::load(d[2])}; }
};

// A group's part in one object visit: the lanes that entered the object,
// their interval, and (in a bone's tree) the group's bound and slack.
struct alignas(32) VisitGroup {
  float t0[kLanes];
  float t1[kLanes];
  // In a bone's tree: the lanes' rays in the bone frame and their slack,
  // for the exact lane clip against a leaf's cell.
  float o[3][kLanes], d[3][kLanes], inv[3][kLanes];
  float lane_eps[kLanes];
  std::uint32_t lanes = 0;       // the lanes that entered the object
  std::uint32_t leaf_lanes = 0;  // of those, the ones whose ray reaches the current leaf (or object)
  Vec3x8 origin() const { return {Float8::load(o[0]), Float8::load(o[1]), Float8::load(o[2])}; }
  Vec3x8 direction() const { return {Float8::load(d[0]), Float8::load(d[1]), Float8::load(d[2])}; }
  Vec3x8 inverse() const { return {Float8::load(inv[0]), Float8::load(inv[1]), Float8::load(inv[2])}; }
};

// A group's world slack for a box of magnitude `box_magnitude` reached up
// to t_end (traverse/ray_frames.h world_slack).
inline Float8 world_eps(const Group& g, float box_magnitude, Float8 t_end) {
  return per_lane::world_slack<Float8>(Float8::load(g.o_mag), Float8::load(g.d_mag), box_magnitude, t_end);
}

// The shared box clip (traverse/ray_frames.h) for the lanes of `mask`.
inline std::uint32_t clip_lanes(const Aabb& box, Float8 eps, const Vec3x8& o, const Vec3x8& d, const Vec3x8& inv,
                                std::uint32_t mask, Float8& t0, Float8& t1) {
  return per_lane::clip_to_box<Float8>(box, eps, o, d, inv, t0, t1).bits() & mask;
}

}  // namespace sinew::rt::packet_lanes
