#include "raytrace/traverse/packet_traversal.h"

#include "raytrace/geometry/triangle_intersect8.h"
#include "raytrace/traverse/traversal_shared.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>

#include "runtime/math/simd.h"

namespace sinew::rt {

Ray RayPacket::ray(int lane) const {
  Ray r;
  r.origin = Vec3(ox[lane], oy[lane], oz[lane]);
  r.direction = Vec3(dx[lane], dy[lane], dz[lane]);
  r.t_min = t_min[lane];
  r.t_max = t_max[lane];
  return r;
}

void RayPacket::set(int lane, const Ray& r) {
  ox[lane] = r.origin.x;
  oy[lane] = r.origin.y;
  oz[lane] = r.origin.z;
  dx[lane] = r.direction.x;
  dy[lane] = r.direction.y;
  dz[lane] = r.direction.z;
  t_min[lane] = r.t_min;
  t_max[lane] = r.t_max;
}

#if SINEW_AVX2
namespace {

using detail::clip_to_box;
using detail::finite;
using detail::max_abs;
using detail::valid_ray;

constexpr int kLanes = kPacketSize;
constexpr float kInf = std::numeric_limits<float>::infinity();

// The helpers below repeat the single-ray traversal's (traverse/traversal.cpp)
// expression for expression: the packet must reach the very cells the single
// ray reaches, so its slack and clipping must round the same way.





template <class Fn>
void for_each_lane(std::uint32_t mask, Fn&& fn) {
  while (mask != 0) {
    const int lane = __builtin_ctz(mask);
    mask &= mask - 1;
    fn(lane);
  }
}

// All-ones in the lanes of `mask`, zero elsewhere.
inline __m256 lane_mask(std::uint32_t mask) {
  const __m256i bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  return _mm256_castsi256_ps(
      _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(static_cast<int>(mask)), bits), bits));
}

// The packet's rays in the frame of the tree being walked (world or a
// bone's), with each lane's slack.
struct alignas(32) FrameRays {
  float o[3][kLanes];
  float d[3][kLanes];
  float inv[3][kLanes];
  float eps[kLanes];

  Vec3 origin(int lane) const { return {o[0][lane], o[1][lane], o[2][lane]}; }
  Vec3 direction(int lane) const { return {d[0][lane], d[1][lane], d[2][lane]}; }
  Vec3 inverse(int lane) const { return {inv[0][lane], inv[1][lane], inv[2][lane]}; }
  void set(int lane, const Vec3& origin, const Vec3& direction) {
    for (int a = 0; a < 3; ++a) {
      o[a][lane] = origin[a];
      d[a][lane] = direction[a];
      inv[a][lane] = 1.0f / direction[a];
    }
  }
};

// Lanes whose interval [t0, t1] is still open, and those intervals.
struct alignas(32) Intervals {
  float t0[kLanes];
  float t1[kLanes];
};

struct alignas(32) StackEntry {
  Intervals span;
  std::uint32_t node;
  std::uint32_t mask;
  // Lanes the single ray would have descended into this child directly
  // (their near child was empty): it does not clip t1 to the best hit there,
  // so neither does the packet when it gets to them.
  std::uint32_t direct;
};

// One inner node for the packet: each lane's below and above intervals
// (thick planes), which child is near, and which lanes reach each child.
struct SplitStep {
  Intervals near;
  Intervals far;
  std::uint32_t near_mask = 0;
  std::uint32_t far_mask = 0;
  bool below_first = true;
  bool coherent = true;
  std::uint32_t negative = 0;  // lanes whose direction is negative along the split axis
};

// Per lane exactly traverse_tree's arithmetic in traversal.cpp, eight lanes
// at once. _mm256_min_ps(x, y) is x < y ? x : y, so
// std::min(t1, x) == _mm256_min_ps(x, t1) and std::max(t0, x) ==
// _mm256_max_ps(x, t0), NaN included.
[[gnu::always_inline]] inline void split_step_avx2(const FrameRays& r, int a, float split, std::uint32_t mask, const Intervals& cur,
                     const float* t_limit, SplitStep& s) {
  const __m256 da = _mm256_load_ps(r.d[a]);
  const __m256 zero = _mm256_setzero_ps();
  const std::uint32_t negative =
      static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(da, zero, _CMP_LT_OQ))) & mask;
  s.negative = negative;
  if (negative != 0 && negative != mask) {
    s.coherent = false;
    return;
  }
  s.coherent = true;
  s.below_first = negative == 0;
  const __m256 t0 = _mm256_load_ps(cur.t0);
  const __m256 t1 = _mm256_load_ps(cur.t1);
  const __m256 oa = _mm256_load_ps(r.o[a]);
  const __m256 inv = _mm256_load_ps(r.inv[a]);
  const __m256 eps = _mm256_load_ps(r.eps);
  const __m256 sp = _mm256_set1_ps(split);
  const __m256 below_edge = _mm256_add_ps(sp, eps);
  const __m256 above_edge = _mm256_sub_ps(sp, eps);
  const __m256 t_below = _mm256_mul_ps(_mm256_sub_ps(below_edge, oa), inv);
  const __m256 t_above = _mm256_mul_ps(_mm256_sub_ps(above_edge, oa), inv);
  const __m256 minus_inf = _mm256_set1_ps(-kInf);
  __m256 n0, n1, f0, f1;
  if (s.below_first) {
    // Positive lanes clip by the plane; zero (or NaN) lanes keep the whole
    // interval for each side their origin lies within.
    const __m256 pos = _mm256_cmp_ps(da, zero, _CMP_GT_OQ);
    const __m256 b1_zero = _mm256_blendv_ps(minus_inf, t1, _mm256_cmp_ps(oa, below_edge, _CMP_LE_OQ));
    const __m256 a1_zero = _mm256_blendv_ps(minus_inf, t1, _mm256_cmp_ps(oa, above_edge, _CMP_GE_OQ));
    n0 = t0;
    n1 = _mm256_blendv_ps(b1_zero, _mm256_min_ps(t_below, t1), pos);
    f0 = _mm256_blendv_ps(t0, _mm256_max_ps(t_above, t0), pos);
    f1 = _mm256_blendv_ps(a1_zero, t1, pos);
  } else {
    n0 = t0;
    n1 = _mm256_min_ps(t_above, t1);
    f0 = _mm256_max_ps(t_below, t0);
    f1 = t1;
  }
  _mm256_store_ps(s.near.t0, n0);
  _mm256_store_ps(s.near.t1, n1);
  _mm256_store_ps(s.far.t0, f0);
  _mm256_store_ps(s.far.t1, f1);
  const __m256 limit = _mm256_loadu_ps(t_limit);
  s.near_mask = static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(n0, n1, _CMP_LE_OQ))) & mask;
  s.far_mask = static_cast<std::uint32_t>(_mm256_movemask_ps(
                   _mm256_and_ps(_mm256_cmp_ps(f0, f1, _CMP_LE_OQ), _mm256_cmp_ps(f0, limit, _CMP_LE_OQ)))) &
               mask;
}

// Pop: lanes whose entry is not beyond their best hit, t1 clipped to it
// (std::min(entry.t1, t_limit) == _mm256_min_ps(t_limit, entry.t1)).
[[gnu::always_inline]] inline std::uint32_t pop_lanes(const StackEntry& e, const float* t_limit, std::uint32_t live, Intervals& cur) {
  const __m256 limit = _mm256_loadu_ps(t_limit);
  const __m256 t0 = _mm256_load_ps(e.span.t0);
  const std::uint32_t mask =
      static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(t0, limit, _CMP_LE_OQ))) & e.mask & live;
  if (mask == 0) return 0;
  const __m256 t1 = _mm256_load_ps(e.span.t1);
  const __m256i lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  const __m256 direct = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
      _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(e.direct)), lane_bits), lane_bits));
  _mm256_store_ps(cur.t0, t0);
  _mm256_store_ps(cur.t1, _mm256_blendv_ps(_mm256_min_ps(limit, t1), t1, direct));
  return mask;
}
// clip_to_box for the lanes in `mask`: each lane's [t0, t1] clipped to
// `box` grown by that lane's eps[lane]; returns the lanes left with t0 <= t1.
[[gnu::always_inline]] inline std::uint32_t clip_lanes(const Aabb& box, const float* eps_lanes, const FrameRays& r, std::uint32_t mask,
                         Intervals& span) {
  const __m256 eps = _mm256_loadu_ps(eps_lanes);
  const __m256 zero = _mm256_setzero_ps();
  __m256 t0 = _mm256_load_ps(span.t0);
  __m256 t1 = _mm256_load_ps(span.t1);
  __m256 outside = zero;
  for (int a = 0; a < 3; ++a) {
    const __m256 lo = _mm256_sub_ps(_mm256_set1_ps(box.lower[a]), eps);
    const __m256 hi = _mm256_add_ps(_mm256_set1_ps(box.upper[a]), eps);
    const __m256 o = _mm256_load_ps(r.o[a]);
    const __m256 inv = _mm256_load_ps(r.inv[a]);
    const __m256 parallel = _mm256_cmp_ps(_mm256_load_ps(r.d[a]), zero, _CMP_EQ_OQ);
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(o, lo, _CMP_GE_OQ), _mm256_cmp_ps(o, hi, _CMP_LE_OQ));
    outside = _mm256_or_ps(outside, _mm256_andnot_ps(inside, parallel));
    const __m256 near = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
    const __m256 far = _mm256_mul_ps(_mm256_sub_ps(hi, o), inv);
    const __m256 swap = _mm256_cmp_ps(near, far, _CMP_GT_OQ);
    const __m256 n = _mm256_blendv_ps(near, far, swap);
    const __m256 f = _mm256_blendv_ps(far, near, swap);
    t0 = _mm256_blendv_ps(_mm256_max_ps(n, t0), t0, parallel);
    t1 = _mm256_blendv_ps(_mm256_min_ps(f, t1), t1, parallel);
  }
  _mm256_store_ps(span.t0, t0);
  _mm256_store_ps(span.t1, t1);
  const std::uint32_t open = static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)));
  return open & ~static_cast<std::uint32_t>(_mm256_movemask_ps(outside)) & mask;
}
// Front-to-back walk of one kd-tree for the lanes in `mask`, from node
// `index` over their intervals `start`. Each lane visits exactly the nodes,
// in exactly the order, the single-ray walk would: lanes only share the
// node fetches. Where the lanes disagree on the near child, the subtree is
// walked once per direction sign (each half agrees on this axis, so the
// recursion is at most three deep). `leaf(items,
// lanes)` returns true to stop (every lane answered).
template <class LeafFn>
bool traverse_packet(const KdTreeView& tree, const FrameRays& r, std::uint32_t index, std::uint32_t mask,
                     const Intervals& start, const float* t_limit, const std::uint32_t& live,
                     std::uint64_t& visits, LeafFn& leaf) {
  std::array<StackEntry, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  Intervals cur = start;
  SplitStep s;
  for (;;) {
    ++visits;
    const KdNode node = tree.nodes[index];
    if (!node.is_leaf()) {
      split_step_avx2(r, node.axis(), node.split(), mask, cur, t_limit, s);
      if (s.coherent) {
        const std::uint32_t below = index + 1;
        const std::uint32_t above = node.above_child();
        const std::uint32_t near_node = s.below_first ? below : above;
        const std::uint32_t far_node = s.below_first ? above : below;
        if (s.near_mask != 0) {
          if (s.far_mask != 0) {
            StackEntry& e = stack[top++];
            e.span = s.far;
            e.node = far_node;
            e.mask = s.far_mask;
            e.direct = s.far_mask & ~s.near_mask;
          }
          index = near_node;
          mask = s.near_mask;
          cur = s.near;
          continue;
        }
        if (s.far_mask != 0) {
          index = far_node;
          mask = s.far_mask;
          cur = s.far;
          continue;
        }
      } else {
        // Two packets, one per sign, each walking the subtree in its own
        // order; a lane finishes the subtree before it pops, as it would alone.
        const std::uint32_t forward = mask & ~s.negative;
        if (traverse_packet(tree, r, index, forward, cur, t_limit, live, visits, leaf)) return true;
        const std::uint32_t backward = mask & s.negative & live;
        if (backward != 0 && traverse_packet(tree, r, index, backward, cur, t_limit, live, visits, leaf)) {
          return true;
        }
      }
    } else if (node.item_count() > 0) {
      if (leaf(tree.items.subspan(node.first_item(), node.item_count()), mask & live)) return true;
    }
    for (;;) {
      if (top == 0) return false;
      const StackEntry& e = stack[--top];
      mask = pop_lanes(e, t_limit, live, cur);
      if (mask != 0) {
        index = e.node;
        break;
      }
    }
  }
}

// Front-to-back walk of one BVH for the lanes in `mask` over their intervals
// `start` (clipped to the root's box by the caller): a lane enters each
// node whose box, grown by its eps, its interval reaches before its best
// hit; of two children both entered, the one with the nearer entry over
// the packet's lanes goes first. Unlike the kd walk the lanes do not keep
// their single ray's order (a BVH's siblings overlap, so no order is the
// rays' own); each still reaches every node its single ray reaches, and
// tests each of the bone's triangles at most once. `leaf(items, lanes)`
// returns true to stop (every lane answered).
template <class LeafFn>
bool traverse_packet_bvh(const BvhView& tree, const FrameRays& r, std::uint32_t mask, const Intervals& start,
                         const float* t_limit, const std::uint32_t& live, std::uint64_t& visits, LeafFn& leaf) {
  struct alignas(32) Pending {
    float t0[kLanes];
    std::uint32_t node;
    std::uint32_t mask;
  };
  std::array<Pending, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  std::uint32_t index = 0;
  const __m256 t0 = _mm256_load_ps(start.t0);
  const __m256 t1 = _mm256_load_ps(start.t1);
  const auto nearest = [](const Intervals& span, std::uint32_t lanes) {
    float m = kInf;
    for (std::uint32_t rest = lanes; rest != 0; rest &= rest - 1) m = std::min(m, span.t0[std::countr_zero(rest)]);
    return m;
  };
  for (;;) {
    ++visits;
    const BvhNode& node = tree.nodes[index];
    if (node.is_leaf()) {
      if (leaf(tree.items.subspan(node.first, node.count), mask & live)) return true;
    } else {
      Intervals a, b;
      const __m256 limited = _mm256_min_ps(_mm256_loadu_ps(t_limit), t1);
      _mm256_store_ps(a.t0, t0);
      _mm256_store_ps(a.t1, limited);
      b = a;
      const std::uint32_t lanes = mask & live;
      const std::uint32_t in_a = clip_lanes(tree.nodes[node.first].box, r.eps, r, lanes, a);
      const std::uint32_t in_b = clip_lanes(tree.nodes[node.first + 1].box, r.eps, r, lanes, b);
      if (in_a != 0 && in_b != 0) {
        const bool a_first = nearest(a, in_a) <= nearest(b, in_b);
        Pending& far = stack[top++];
        std::memcpy(far.t0, a_first ? b.t0 : a.t0, sizeof far.t0);
        far.node = a_first ? node.first + 1 : node.first;
        far.mask = a_first ? in_b : in_a;
        index = a_first ? node.first : node.first + 1;
        mask = a_first ? in_a : in_b;
        continue;
      }
      if ((in_a | in_b) != 0) {
        index = in_a != 0 ? node.first : node.first + 1;
        mask = in_a | in_b;
        continue;
      }
    }
    for (;;) {
      if (top == 0) return false;
      const Pending& e = stack[--top];
      const __m256 ahead = _mm256_cmp_ps(_mm256_load_ps(e.t0), _mm256_loadu_ps(t_limit), _CMP_LE_OQ);
      mask = static_cast<std::uint32_t>(_mm256_movemask_ps(ahead)) & e.mask & live;
      if (mask != 0) {
        index = e.node;
        break;
      }
    }
  }
}

// Per object, the triangles already tested and by which lanes: a triangle
// whose fuzzy box straddles splits is listed in several leaves, and a lane
// may reach it through each. Direct-mapped on the id's low bits like the
// single ray's Mailbox; a lane that tests a triangle twice (after an
// eviction) gets the same answer, which cannot beat its best t strictly.
class PacketMailbox {
 public:
  void reset() { ids_.fill(kInvalidId); }
  // Of `lanes`, those that have not tested `id` yet (marking them).
  std::uint32_t untested(std::uint32_t id, std::uint32_t lanes) {
    const std::size_t slot = id & (ids_.size() - 1);
    if (ids_[slot] != id) {
      ids_[slot] = id;
      lanes_[slot] = lanes;
      return lanes;
    }
    const std::uint32_t fresh = lanes & ~lanes_[slot];
    lanes_[slot] |= lanes;
    return fresh;
  }

 private:
  std::array<std::uint32_t, 16> ids_{};
  std::array<std::uint32_t, 16> lanes_{};
};

// One packet query: per lane the world ray, its triangle-test data and its
// best (closest-hit) or first (any-hit) hit; per lane the same state the
// single-ray Query keeps.
template <TriangleTest kTest, bool kAnyHit>
class PacketQuery {
 public:
  PacketQuery(const Scene& scene, const RayPacket& packet) : scene_(scene) {
    // valid_ray() for eight lanes: finite origin and direction, a non-zero
    // direction, t_min < t_max (false for NaN).
    const __m256 max = _mm256_set1_ps(std::numeric_limits<float>::max());
    const __m256 sign = _mm256_set1_ps(-0.0f);
    const __m256 zero = _mm256_setzero_ps();
    const float* const origin[3] = {packet.ox, packet.oy, packet.oz};
    const float* const direction[3] = {packet.dx, packet.dy, packet.dz};
    __m256 o[3], d[3];
    __m256 valid = _mm256_cmp_ps(_mm256_loadu_ps(packet.t_min), _mm256_loadu_ps(packet.t_max), _CMP_LT_OQ);
    __m256 nonzero = _mm256_setzero_ps();
    for (int a = 0; a < 3; ++a) {
      o[a] = _mm256_loadu_ps(origin[a]);
      d[a] = _mm256_loadu_ps(direction[a]);
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(_mm256_andnot_ps(sign, o[a]), max, _CMP_LE_OQ));
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(_mm256_andnot_ps(sign, d[a]), max, _CMP_LE_OQ));
      nonzero = _mm256_or_ps(nonzero, _mm256_cmp_ps(d[a], zero, _CMP_NEQ_OQ));
    }
    live_ = static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_and_ps(valid, nonzero))) & packet.active;
    valid_ = live_;
    // Other lanes get the default Ray{}, so the eight-wide arithmetic stays finite.
    const __m256 use = lane_mask(live_);
    const Ray none{};
    __m256 o_mag = zero, d_mag = zero;
    for (int a = 0; a < 3; ++a) {
      o[a] = _mm256_blendv_ps(_mm256_set1_ps(none.origin[a]), o[a], use);
      d[a] = _mm256_blendv_ps(_mm256_set1_ps(none.direction[a]), d[a], use);
      _mm256_store_ps(world_.o[a], o[a]);
      _mm256_store_ps(world_.d[a], d[a]);
      // 1 / d, correctly rounded like the single ray's.
      _mm256_store_ps(world_.inv[a], _mm256_div_ps(_mm256_set1_ps(1.0f), d[a]));
      o_mag = _mm256_max_ps(o_mag, _mm256_andnot_ps(sign, o[a]));
      d_mag = _mm256_max_ps(d_mag, _mm256_andnot_ps(sign, d[a]));
    }
    _mm256_store_ps(world_.eps, zero);
    _mm256_store_ps(origin_magnitude_, o_mag);
    _mm256_store_ps(direction_magnitude_, d_mag);
    _mm256_store_ps(t_min_, _mm256_blendv_ps(_mm256_set1_ps(none.t_min), _mm256_loadu_ps(packet.t_min), use));
    _mm256_store_ps(t_limit_, _mm256_blendv_ps(_mm256_set1_ps(none.t_max), _mm256_loadu_ps(packet.t_max), use));
    if constexpr (kTest == TriangleTest::kWatertight) {
      for (int lane = 0; lane < kLanes; ++lane) watertight_[lane] = prepare_watertight(ray(lane));
    }
  }

  void run(const ObjectFilter* filter) {
    filter_ = filter;
    const KdTreeView top = scene_.top_level().view();
    if (top.empty() || live_ == 0 || (filter_ != nullptr && filter_->objects.empty())) return;
    // The whole scene's box: slack for the box alone, then for the ray's
    // reach to its far side (the single-ray query's two steps).
    const float box_magnitude = max_abs(top.bounds);
    Intervals span;
    _mm256_store_ps(span.t0, _mm256_load_ps(t_min_));
    _mm256_store_ps(span.t1, _mm256_load_ps(t_limit_));
    alignas(32) float eps[kLanes];
    _mm256_store_ps(eps, world_eps8(box_magnitude, _mm256_setzero_ps()));
    const std::uint32_t mask = clip_lanes(top.bounds, eps, world_, live_, span);
    if (mask == 0) return;
    _mm256_store_ps(world_.eps, world_eps8(box_magnitude, _mm256_load_ps(span.t1)));
    if (filter_ != nullptr) {
      // The culled objects front to back: each visit covers each lane's
      // whole ray up to its best hit, as the walk's first leaf holding the
      // object would, and skips lanes whose best hit lies before the box.
      for (const std::uint32_t object : filter_->objects) {
        if ((mask & live_) == 0) return;
        if (visit(scene_.top_level().objects()[object], mask & live_)) return;
      }
      return;
    }
    auto leaf = [this](std::span<const std::uint32_t> objects, std::uint32_t lanes) {
      for (const std::uint32_t object : objects) {
        const std::uint32_t entering = lanes_entering(object, lanes & live_);
        if (entering != 0 && visit(scene_.top_level().objects()[object], entering)) return true;
      }
      return false;
    };
    traverse_packet(top, world_, 0, mask, span, t_limit_, live_, counters_.node_visits, leaf);
  }

  const Hit& hit(int lane) const { return best_[lane]; }
  std::uint32_t valid_lanes() const { return valid_; }
  const TraversalCounters& counters() const { return counters_; }

 private:
  // Per lane the single-ray query's slack for a world-space box of
  // magnitude max_abs(box) reached up to t_end: kFrameRelativeSlack *
  // ((|origin| + t_end * |direction|) + box_magnitude), the reach taken as 0
  // for an infinite t_end.
  __m256 world_eps8(float box_magnitude, __m256 t_end) const {
    const __m256 finite_end = _mm256_cmp_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), t_end),
                                            _mm256_set1_ps(std::numeric_limits<float>::max()), _CMP_LE_OQ);
    const __m256 reach =
        _mm256_and_ps(finite_end, _mm256_mul_ps(t_end, _mm256_load_ps(direction_magnitude_)));
    const __m256 sum = _mm256_add_ps(_mm256_add_ps(_mm256_load_ps(origin_magnitude_), reach),
                                     _mm256_set1_ps(box_magnitude));
    return _mm256_mul_ps(_mm256_set1_ps(kFrameRelativeSlack), sum);
  }

  Ray ray(int lane) const {
    Ray r;
    r.origin = world_.origin(lane);
    r.direction = world_.direction(lane);
    r.t_min = t_min_[lane];
    r.t_max = t_limit_[lane];
    return r;
  }

  // Of `lanes`, those that have not entered `object` yet (marking them).
  // Objects overlap several top-level leaves and each lane traverses an
  // object once, over its whole ray. Past the list's capacity an object may
  // be entered again: that costs time but changes no hit (a triangle must
  // beat the best t strictly), as in the single-ray query.
  std::uint32_t lanes_entering(std::uint32_t object, std::uint32_t lanes) {
    for (std::size_t i = 0; i < visited_count_; ++i) {
      if (visited_objects_[i] == object) {
        const std::uint32_t entering = lanes & ~visited_lanes_[i];
        visited_lanes_[i] |= lanes;
        return entering;
      }
    }
    if (visited_count_ < visited_objects_.size()) {
      visited_objects_[visited_count_] = object;
      visited_lanes_[visited_count_++] = lanes;
    }
    return lanes;
  }

  bool visit(const TopLevelObject& object, std::uint32_t lanes) {
    Intervals span;
    alignas(32) float eps[kLanes];
    const __m256 t_limit = _mm256_load_ps(t_limit_);
    _mm256_store_ps(span.t0, _mm256_load_ps(t_min_));
    _mm256_store_ps(span.t1, t_limit);
    _mm256_store_ps(eps, world_eps8(max_abs(object.box), t_limit));
    const std::uint32_t mask = clip_lanes(object.box, eps, world_, lanes, span);
    if (mask == 0) return false;
    mailbox_.reset();
    counters_.object_visits += static_cast<std::uint64_t>(std::popcount(mask));
    switch (object.kind) {
      case TopLevelObject::Kind::kBone:
        return visit_bone(scene_.instances()[object.index], object.bone, mask, span);
      case TopLevelObject::Kind::kStatic:
        return visit_static(scene_.static_meshes()[object.index], mask, span);
      case TopLevelObject::Kind::kFallback:
        return visit_fallback(scene_.instances()[object.index], mask, span);
    }
    return false;
  }

  bool visit_bone(const InstanceFrame& frame, std::uint32_t bone, std::uint32_t lanes, Intervals& span) {
    const Scene::Character& character = scene_.characters()[frame.character];
    const BoneTree& tree = frame.bone_tree(character.fuzzy, bone);
    const Affine3& to_bone = frame.bone_from_world[bone];
    const InstanceFrame::BoneCarry& carry = frame.bone_carry[bone];
    // Per lane Affine3::transform_point / transform_vector, term by term in
    // the same order; inactive lanes get o = 0, d = 1 and no slack.
    FrameRays local;
    const __m256 use = lane_mask(lanes);
    const __m256 sign = _mm256_set1_ps(-0.0f);
    const __m256 wo[3] = {_mm256_load_ps(world_.o[0]), _mm256_load_ps(world_.o[1]), _mm256_load_ps(world_.o[2])};
    const __m256 wd[3] = {_mm256_load_ps(world_.d[0]), _mm256_load_ps(world_.d[1]), _mm256_load_ps(world_.d[2])};
    __m256 o_mag = _mm256_setzero_ps(), d_mag = _mm256_setzero_ps();
    for (int a = 0; a < 3; ++a) {
      const Vec4& row = to_bone.rows[a];
      const __m256 rx = _mm256_set1_ps(row.x), ry = _mm256_set1_ps(row.y), rz = _mm256_set1_ps(row.z);
      const __m256 linear_o =
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(rx, wo[0]), _mm256_mul_ps(ry, wo[1])), _mm256_mul_ps(rz, wo[2]));
      const __m256 o = _mm256_and_ps(use, _mm256_add_ps(linear_o, _mm256_set1_ps(row.w)));
      const __m256 d = _mm256_blendv_ps(
          _mm256_set1_ps(1.0f),
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(rx, wd[0]), _mm256_mul_ps(ry, wd[1])), _mm256_mul_ps(rz, wd[2])),
          use);
      _mm256_store_ps(local.o[a], o);
      _mm256_store_ps(local.d[a], d);
      // 1 / d, correctly rounded like the single ray's.
      _mm256_store_ps(local.inv[a], _mm256_div_ps(_mm256_set1_ps(1.0f), d));
      o_mag = _mm256_max_ps(o_mag, _mm256_andnot_ps(sign, o));
      d_mag = _mm256_max_ps(d_mag, _mm256_andnot_ps(sign, d));
    }
    // 2 tolerance + slack * (((carried + |o|) + t1 |d|) + |bounds|), with
    // carried = linear_norm * |world origin| + translation magnitude.
    const __m256 carried = _mm256_add_ps(
        _mm256_mul_ps(_mm256_set1_ps(carry.linear_norm), _mm256_load_ps(origin_magnitude_)),
        _mm256_set1_ps(carry.translation_magnitude));
    const __m256 sum = _mm256_add_ps(
        _mm256_add_ps(_mm256_add_ps(carried, o_mag), _mm256_mul_ps(_mm256_load_ps(span.t1), d_mag)),
        _mm256_set1_ps(carry.bounds_magnitude));
    const __m256 eps = _mm256_add_ps(_mm256_set1_ps(2.0f * frame.tolerance[bone]),
                                     _mm256_mul_ps(_mm256_set1_ps(kFrameRelativeSlack), sum));
    _mm256_store_ps(local.eps, _mm256_and_ps(use, eps));
    const std::uint32_t mask = clip_lanes(tree.bounds, local.eps, local, lanes, span);
    if (mask == 0) return false;
    const SkinnedMesh& mesh = *character.mesh;
    auto leaf = [&](std::span<const std::uint32_t> triangles, std::uint32_t active) {
      for (const std::uint32_t t : triangles) {
        const auto& v = mesh.triangles[t];
        if (test(active, frame.positions[v[0]], frame.positions[v[1]], frame.positions[v[2]], t,
                 frame.instance_id, t)) {
          return true;
        }
      }
      return false;
    };
    if (character.fuzzy.has_bvhs()) {
      return traverse_packet_bvh(character.fuzzy.bvh_view(tree), local, mask, span, t_limit_, live_,
                                 counters_.node_visits, leaf);
    }
    return traverse_packet(character.fuzzy.tree_view(tree), local, 0, mask, span, t_limit_, live_,
                           counters_.node_visits, leaf);
  }

  bool visit_static(const Scene::StaticMesh& mesh, std::uint32_t lanes, const Intervals& span) {
    if (mesh.desc.triangles.size() <= detail::kBruteForceStaticTriangles) {
      for (std::uint32_t t = 0; t < mesh.desc.triangles.size(); ++t) {
        const auto& v = mesh.desc.triangles[t];
        if (test(lanes, mesh.desc.positions[v[0]], mesh.desc.positions[v[1]], mesh.desc.positions[v[2]], t,
                 mesh.instance_id, t)) {
          return true;
        }
      }
      return false;
    }
    const KdTreeView tree = mesh.tree.view();
    auto leaf = [&](std::span<const std::uint32_t> triangles, std::uint32_t active) {
      for (const std::uint32_t t : triangles) {
        const auto& v = mesh.desc.triangles[t];
        if (test(active, mesh.desc.positions[v[0]], mesh.desc.positions[v[1]], mesh.desc.positions[v[2]], t,
                 mesh.instance_id, t)) {
          return true;
        }
      }
      return false;
    };
    return walk_world_tree(tree, lanes, span, leaf);
  }

  bool visit_fallback(const InstanceFrame& frame, std::uint32_t lanes, const Intervals& span) {
    const SkinnedMesh& mesh = *scene_.characters()[frame.character].mesh;
    const KdTreeView tree = frame.fallback.view();
    auto leaf = [&](std::span<const std::uint32_t> items, std::uint32_t active) {
      for (const std::uint32_t item : items) {
        const std::uint32_t t = frame.escaped_triangles[item];
        const auto& v = mesh.triangles[t];
        if (test(active, frame.positions[v[0]], frame.positions[v[1]], frame.positions[v[2]], t,
                 frame.instance_id, item)) {
          return true;
        }
      }
      return false;
    };
    return walk_world_tree(tree, lanes, span, leaf);
  }

  // A world-space tree below the top level: the world rays with this
  // tree's slack (the top level's own stays in world_ for its walk).
  template <class LeafFn>
  bool walk_world_tree(const KdTreeView& tree, std::uint32_t lanes, const Intervals& span, LeafFn& leaf) {
    FrameRays rays = world_;
    _mm256_store_ps(rays.eps, world_eps8(max_abs(tree.bounds), _mm256_load_ps(span.t1)));
    return traverse_packet(tree, rays, 0, lanes, span, t_limit_, live_, counters_.node_visits, leaf);
  }

  // Tests one world-space triangle for every lane in `lanes` that has not
  // tested it in this object (`mail`: the id the single ray mailboxes).
  // Returns true when every lane is answered (any-hit).
  bool test(std::uint32_t lanes, const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint32_t triangle,
            std::uint32_t instance, std::uint32_t mail) {
    const std::uint32_t untested_lanes = mailbox_.untested(mail, lanes & live_);
    if (untested_lanes == 0) return false;
    counters_.triangle_tests += static_cast<std::uint64_t>(std::popcount(untested_lanes));
    if constexpr (kTest == TriangleTest::kWatertight) {
      for_each_lane(untested_lanes, [&](int lane) {
        TriangleHit h;
        if (intersect_triangle_watertight(watertight_[lane], ray(lane), t_limit_[lane], p0, p1, p2, h)) {
          record(lane, h.t, h.u, h.v, triangle, instance);
        }
      });
    } else {
      alignas(32) float t[kLanes], u[kLanes], v[kLanes];
      const RayLanes8 lanes8{world_.o, world_.d, t_min_, t_limit_};
      const std::uint32_t hit = intersect_triangle_fast8(lanes8, untested_lanes, p0, p1, p2, t, u, v);
      // The scalar test's last check, once per triangle.
      if (hit != 0 && !detail::zero_area(p1 - p0, p2 - p0)) {
        for_each_lane(hit, [&](int lane) { record(lane, t[lane], u[lane], v[lane], triangle, instance); });
      }
    }
    return kAnyHit && live_ == 0;
  }

  void record(int lane, float t, float u, float v, std::uint32_t triangle, std::uint32_t instance) {
    best_[lane] = Hit{t, u, v, triangle, instance};
    if constexpr (kAnyHit) {
      // Answered: retire the lane; -inf also prunes every cell left for it.
      live_ &= ~(1u << lane);
      t_limit_[lane] = -kInf;
    } else {
      t_limit_[lane] = t;
    }
  }

  const Scene& scene_;
  const ObjectFilter* filter_ = nullptr;
  FrameRays world_;
  alignas(32) float t_limit_[kLanes];
  alignas(32) float t_min_[kLanes];
  alignas(32) float origin_magnitude_[kLanes];
  alignas(32) float direction_magnitude_[kLanes];
  std::array<WatertightRay, kLanes> watertight_;
  std::array<Hit, kLanes> best_;
  PacketMailbox mailbox_;
  // The first visited_count_ objects entered, and by which lanes.
  std::array<std::uint32_t, 64> visited_objects_;
  std::array<std::uint32_t, 64> visited_lanes_;
  std::size_t visited_count_ = 0;
  std::uint32_t live_ = 0;
  std::uint32_t valid_ = 0;
  TraversalCounters counters_;
};

void accumulate(TraversalCounters* into, const TraversalCounters& from, std::uint32_t rays) {
  if (!into) return;
  into->rays += static_cast<std::uint64_t>(std::popcount(rays));
  into->node_visits += from.node_visits;
  into->object_visits += from.object_visits;
  into->triangle_tests += from.triangle_tests;
}

template <TriangleTest kTest>
void closest_hits(const Scene& scene, const RayPacket& packet, Hit hits[kPacketSize], TraversalCounters* counters,
                  const ObjectFilter* filter) {
  PacketQuery<kTest, false> query(scene, packet);
  query.run(filter);
  for (int lane = 0; lane < kLanes; ++lane) hits[lane] = query.hit(lane);
  accumulate(counters, query.counters(), query.valid_lanes());
}

template <TriangleTest kTest>
std::uint8_t any_hits(const Scene& scene, const RayPacket& packet, TraversalCounters* counters,
                      const ObjectFilter* filter) {
  PacketQuery<kTest, true> query(scene, packet);
  query.run(filter);
  std::uint8_t bits = 0;
  for (int lane = 0; lane < kLanes; ++lane) {
    if (query.hit(lane).valid()) bits = static_cast<std::uint8_t>(bits | (1u << lane));
  }
  accumulate(counters, query.counters(), query.valid_lanes());
  return bits;
}

// Every triangle of the filter's static meshes against the packet, in
// order, as PacketQuery::test does for kFast: a lane records a hit that is
// strictly nearer than its best so far; any-hit lanes retire on a hit.
template <bool kAnyHit>
std::uint32_t small_statics(const Scene& scene, const RayPacket& packet, const ObjectFilter& filter,
                            float* best_t, float* best_u, float* best_v, std::uint32_t* best_triangle,
                            std::uint32_t* best_instance, TraversalCounters* counters) {
  alignas(32) float o[3][kLanes], d[3][kLanes], t_limit[kLanes];
  std::memcpy(o[0], packet.ox, sizeof(o[0]));
  std::memcpy(o[1], packet.oy, sizeof(o[1]));
  std::memcpy(o[2], packet.oz, sizeof(o[2]));
  std::memcpy(d[0], packet.dx, sizeof(d[0]));
  std::memcpy(d[1], packet.dy, sizeof(d[1]));
  std::memcpy(d[2], packet.dz, sizeof(d[2]));
  std::memcpy(t_limit, packet.t_max, sizeof(t_limit));
  const RayLanes8 lanes8{o, d, packet.t_min, t_limit};
  std::uint32_t live = packet.active;
  std::uint32_t blocked = 0;
  std::uint64_t tests = 0;
  const std::span<const TopLevelObject> objects = scene.top_level().objects();
  for (const std::uint32_t object : filter.objects) {
    const Scene::StaticMesh& mesh = scene.static_meshes()[objects[object].index];
    for (std::uint32_t tri = 0; tri < mesh.desc.triangles.size() && live != 0; ++tri) {
      const auto& v = mesh.desc.triangles[tri];
      const Vec3& p0 = mesh.desc.positions[v[0]];
      const Vec3& p1 = mesh.desc.positions[v[1]];
      const Vec3& p2 = mesh.desc.positions[v[2]];
      tests += static_cast<std::uint64_t>(std::popcount(live));
      alignas(32) float t[kLanes], u[kLanes], w[kLanes];
      const std::uint32_t hit = intersect_triangle_fast8(lanes8, live, p0, p1, p2, t, u, w);
      if (hit == 0 || detail::zero_area(p1 - p0, p2 - p0)) continue;
      if constexpr (kAnyHit) {
        blocked |= hit;
        live &= ~hit;
      } else {
        for_each_lane(hit, [&](int lane) {
          t_limit[lane] = t[lane];
          best_t[lane] = t[lane];
          best_u[lane] = u[lane];
          best_v[lane] = w[lane];
          best_triangle[lane] = tri;
          best_instance[lane] = mesh.instance_id;
        });
      }
    }
  }
  if (counters) {
    counters->rays += static_cast<std::uint64_t>(std::popcount(static_cast<std::uint32_t>(packet.active)));
    counters->object_visits += filter.objects.size() * static_cast<std::uint64_t>(std::popcount(
                                                            static_cast<std::uint32_t>(packet.active)));
    counters->triangle_tests += tests;
  }
  return blocked;
}

}  // namespace

bool intersect_packet_small_statics(const Scene& scene, const RayPacket& packet, TriangleTest test,
                                    const ObjectFilter& filter, PacketHits out, TraversalCounters* counters) {
  if (!detail::small_statics_only(scene, test, filter.objects)) return false;
  for (int lane = 0; lane < kLanes; ++lane) {
    out.t[lane] = kInf;
    out.u[lane] = out.v[lane] = 0.0f;
    out.triangle[lane] = out.instance[lane] = kInvalidId;
  }
  small_statics<false>(scene, packet, filter, out.t, out.u, out.v, out.triangle, out.instance, counters);
  return true;
}

int occluded_packet_small_statics(const Scene& scene, const RayPacket& packet, TriangleTest test,
                                  const ObjectFilter& filter, TraversalCounters* counters) {
  if (!detail::small_statics_only(scene, test, filter.objects)) return -1;
  return static_cast<int>(small_statics<true>(scene, packet, filter, nullptr, nullptr, nullptr, nullptr, nullptr,
                                              counters));
}

void intersect_packet(const Scene& scene, const RayPacket& packet, TriangleTest test, Hit hits[kPacketSize],
                      TraversalCounters* counters, const ObjectFilter* filter) {
  if (test == TriangleTest::kWatertight) {
    closest_hits<TriangleTest::kWatertight>(scene, packet, hits, counters, filter);
  } else {
    closest_hits<TriangleTest::kFast>(scene, packet, hits, counters, filter);
  }
}

std::uint8_t occluded_packet(const Scene& scene, const RayPacket& packet, TriangleTest test,
                             TraversalCounters* counters, const ObjectFilter* filter) {
  return test == TriangleTest::kWatertight ? any_hits<TriangleTest::kWatertight>(scene, packet, counters, filter)
                                           : any_hits<TriangleTest::kFast>(scene, packet, counters, filter);
}

#else

// Without AVX2 the lanes gain nothing from walking together: each is the
// single-ray query itself.
void intersect_packet(const Scene& scene, const RayPacket& packet, TriangleTest test, Hit hits[kPacketSize],
                      TraversalCounters* counters, const ObjectFilter* /*filter: culling only saves time*/) {
  for (int lane = 0; lane < kPacketSize; ++lane) {
    hits[lane] = (packet.active >> lane & 1u) ? intersect(scene, packet.ray(lane), test, counters) : Hit{};
  }
}

std::uint8_t occluded_packet(const Scene& scene, const RayPacket& packet, TriangleTest test,
                             TraversalCounters* counters, const ObjectFilter* /*filter*/) {
  std::uint8_t bits = 0;
  for (int lane = 0; lane < kPacketSize; ++lane) {
    if ((packet.active >> lane & 1u) && occluded(scene, packet.ray(lane), test, counters)) {
      bits = static_cast<std::uint8_t>(bits | (1u << lane));
    }
  }
  return bits;
}

bool intersect_packet_small_statics(const Scene&, const RayPacket&, TriangleTest, const ObjectFilter&, PacketHits,
                                    TraversalCounters*) {
  return false;
}

int occluded_packet_small_statics(const Scene&, const RayPacket&, TriangleTest, const ObjectFilter&,
                                  TraversalCounters*) {
  return -1;
}

#endif  // SINEW_AVX2

}  // namespace sinew::rt
