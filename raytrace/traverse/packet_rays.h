// A large packet's rays (traverse/large_packet.h) as the packet core holds
// them: per group of eight, the world rays with their magnitudes and
// reciprocals, the live lanes (valid, active, not yet answered), each
// group's part in the current object visit, and the triangle tests that
// record a lane's nearest hit or retire a blocked lane. The core
// (traverse/large_packet.cpp) decides which lanes test which triangle;
// this decides what a test does, as the single ray's test does per lane.
// Private to traverse/.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/geometry/triangle_intersect8.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/traverse/packet_lanes.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/math/float8.h"

namespace sinew::rt::packet_lanes {

// The calling thread's query object (tens of kilobytes, reused by every
// packet). Returned by a call that is never inlined, so a packet looks the
// thread-local object up once: inlined into the query's loops, each member
// access would look it up again, behind the register spills of a call.
template <class Query>
[[gnu::noinline]] Query& thread_query() {
  thread_local Query query;
  return query;
}

template <TriangleTest kTest, bool kAnyHit>
class PacketRays {
 public:
  // Loads a packet: every group's valid lanes, misses written to `out`
  // (closest hit). The state is tens of kilobytes, so one object per
  // thread is reused and start() resets what one packet reads.
  void start(const LargePacketRays& rays, PacketHits out) {
    out_ = out;
    groups_ = std::clamp(rays.groups, 0, kMaxPacketGroups);
    alive_groups_ = 0;
    limits_lowered_ = 0;
    common_origin_ = false;
    counters_ = {};
    const Ray none{};
    for (int g = 0; g < groups_; ++g) {
      const std::size_t k0 = static_cast<std::size_t>(g) * kLanes;
      Group& gr = group_[g];
      // The rays the single ray accepts (traverse/ray_frames.h valid_rays).
      const Float8 t_min = Float8::load(rays.t_min + k0), t_max = Float8::load(rays.t_max + k0);
      Float8 o[3], d[3];
      for (int a = 0; a < 3; ++a) {
        o[a] = Float8::load(rays.o[a] + k0);
        d[a] = Float8::load(rays.d[a] + k0);
      }
      const Mask8 valid = per_lane::valid_rays<Float8>({o[0], o[1], o[2]}, {d[0], d[1], d[2]}, t_min, t_max);
      live_[g] = valid.bits() & rays.active[g];
      valid_[g] = live_[g];
      blocked_[g] = 0;
      const Mask8 use = Mask8::from_bits(live_[g]);
      Float8 o_mag(0.0f), d_mag(0.0f);
      for (int a = 0; a < 3; ++a) {
        o[a] = select(use, o[a], Float8(none.origin[a]));
        d[a] = select(use, d[a], Float8(none.direction[a]));
        o[a].store(gr.o[a]);
        d[a].store(gr.d[a]);
        o_mag = max(o_mag, abs(o[a]));
        d_mag = max(d_mag, abs(d[a]));
      }
      o_mag.store(gr.o_mag);
      d_mag.store(gr.d_mag);
      select(use, t_min, Float8(none.t_min)).store(gr.t_min);
      select(use, t_max, Float8(none.t_max)).store(gr.t_limit);
      if (live_[g] != 0) {
        if (alive_groups_ == 0) {
          const int lane = std::countr_zero(live_[g]);
          common_origin_at_ = Vec3(gr.o[0][lane], gr.o[1][lane], gr.o[2][lane]);
          common_origin_ = true;
        }
        const Mask8 same = (o[0] == Float8(common_origin_at_.x)) & (o[1] == Float8(common_origin_at_.y)) &
                           (o[2] == Float8(common_origin_at_.z));
        common_origin_ = common_origin_ && (same.bits() & live_[g]) == live_[g];
        alive_groups_ |= GroupMask{1} << g;
      }
      if constexpr (kTest == TriangleTest::kWatertight) {
        for_each_bit(live_[g], [&](int lane) { watertight_[g][lane] = prepare_watertight(world_ray(g, lane)); });
      }
      if constexpr (!kAnyHit) {
        Float8(kInf).store(out_.t + k0);
        Float8(0.0f).store(out_.u + k0);
        Float8(0.0f).store(out_.v + k0);
        std::fill_n(out_.triangle + k0, kLanes, kInvalidId);
        std::fill_n(out_.instance + k0, kLanes, kInvalidId);
      }
    }
  }

  // After a packet: each group's blocked lanes into blocked[g] (any hit;
  // may be null) and the packet's work added to `counters` (may be null),
  // counted for its valid rays.
  void finish(std::uint8_t* blocked, TraversalCounters* counters) const {
    std::uint64_t rays_valid = 0;
    for (int g = 0; g < groups_; ++g) {
      rays_valid += static_cast<std::uint64_t>(std::popcount(valid_[g]));
      if (blocked) blocked[g] = static_cast<std::uint8_t>(blocked_[g]);
    }
    if (counters) *counters += counters_.for_rays(rays_valid);
  }

 protected:
  // The largest t any lane of `groups` still looks for: its best hit (or
  // t_max), capped by its exit from the current object when `visit` holds it.
  float packet_limit(GroupMask groups, const VisitGroup* visit) const {
    float limit = -kInf;
    for_each_bit(groups, [&](int g) { limit = std::max(limit, group_limit(g, visit)); });
    return limit;
  }
  float group_limit(int g, const VisitGroup* visit) const {
    const std::uint32_t lanes = visit ? visit[g].lanes & live_[g] : live_[g];
    if (lanes == 0) return -kInf;
    Float8 t = Float8::load(group_[g].t_limit);
    if (visit) t = min(t, Float8::load(visit[g].t1));
    return reduce_max(select(Mask8::from_bits(lanes), t, Float8(-kInf)));
  }

  Ray world_ray(int g, int lane) const {
    const Group& gr = group_[g];
    Ray r;
    r.origin = Vec3(gr.o[0][lane], gr.o[1][lane], gr.o[2][lane]);
    r.direction = Vec3(gr.d[0][lane], gr.d[1][lane], gr.d[2][lane]);
    r.t_min = gr.t_min[lane];
    r.t_max = gr.t_limit[lane];
    return r;
  }

  // Tests one world-space triangle for the live lanes of each group of
  // `groups` that reach it (visit_[g].leaf_lanes).
  void test_groups(GroupMask groups, const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint32_t triangle,
                   std::uint32_t instance) {
    if constexpr (kTest == TriangleTest::kFast) {
      if (common_origin_) {
        test_groups_prepared(groups, prepare_common_origin(common_origin_at_, p0, p1, p2), triangle, instance);
        return;
      }
    }
    for_each_bit(groups, [&](int g) { test(g, visit_[g].leaf_lanes, p0, p1, p2, triangle, instance); });
  }

  // test_groups with the fast test for rays from common_origin_at_, the
  // triangle's origin terms prepared: once for every group; the zero-area
  // check of the scalar test once per triangle, on the hit path.
  void test_groups_prepared(GroupMask groups, const CommonOriginTriangle& c, std::uint32_t triangle,
                            std::uint32_t instance) {
    int zero_area = -1;
    for_each_bit(groups, [&](int g) {
      const std::uint32_t lanes = visit_[g].leaf_lanes & live_[g];
      if (lanes == 0) return;
      counters_.triangle_tests += static_cast<std::uint64_t>(std::popcount(lanes));
      Group& gr = group_[g];
      alignas(32) float t[kLanes], u[kLanes], v[kLanes];
      const RayLanes8 lanes8{gr.o, gr.d, gr.t_min, gr.t_limit};
      const std::uint32_t hit = intersect_triangle_fast8_common_origin(lanes8, lanes, c, t, u, v);
      if (hit == 0) return;
      if (zero_area < 0) zero_area = detail::zero_area(c.e1, c.e2) ? 1 : 0;
      if (zero_area == 0) record_lanes(g, hit, t, u, v, triangle, instance);
    });
  }

  // Tests one world-space triangle for the live lanes of `lanes` of group g.
  void test(int g, std::uint32_t lanes, const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint32_t triangle,
            std::uint32_t instance) {
    lanes &= live_[g];
    if (lanes == 0) return;
    counters_.triangle_tests += static_cast<std::uint64_t>(std::popcount(lanes));
    Group& gr = group_[g];
    if constexpr (kTest == TriangleTest::kWatertight) {
      for_each_bit(lanes, [&](int lane) {
        TriangleHit h;
        if (intersect_triangle_watertight(watertight_[g][lane], world_ray(g, lane), gr.t_limit[lane], p0, p1, p2,
                                          h)) {
          if constexpr (kAnyHit) {
            retire(g, lane);
          } else {
            record(g, lane, h.t, h.u, h.v, triangle, instance);
          }
        }
      });
    } else {
      alignas(32) float t[kLanes], u[kLanes], v[kLanes];
      const RayLanes8 lanes8{gr.o, gr.d, gr.t_min, gr.t_limit};
      const std::uint32_t hit = intersect_triangle_fast8(lanes8, lanes, p0, p1, p2, t, u, v);
      // The scalar test's last check, once per triangle.
      if (hit == 0 || detail::zero_area(p1 - p0, p2 - p0)) return;
      if constexpr (kAnyHit) {
        for_each_bit(hit, [&](int lane) { retire(g, lane); });
      } else {
        record_lanes(g, hit, t, u, v, triangle, instance);
      }
    }
  }

  // The hits of `lanes` of group g, eight lanes at once.
  void record_lanes(int g, std::uint32_t lanes, const float* t, const float* u, const float* v,
                    std::uint32_t triangle, std::uint32_t instance) {
    if constexpr (kAnyHit) {
      for_each_bit(lanes, [&](int lane) { retire(g, lane); });
    } else {
      const std::size_t k0 = static_cast<std::size_t>(g) * kLanes;
      const Mask8 m = Mask8::from_bits(lanes);
      const Float8 tt = Float8::load(t);
      select(m, tt, Float8::load(group_[g].t_limit)).store(group_[g].t_limit);
      select(m, tt, Float8::load(out_.t + k0)).store(out_.t + k0);
      select(m, Float8::load(u), Float8::load(out_.u + k0)).store(out_.u + k0);
      select(m, Float8::load(v), Float8::load(out_.v + k0)).store(out_.v + k0);
      store_where(m, triangle, out_.triangle + k0);
      store_where(m, instance, out_.instance + k0);
      limits_lowered_ |= GroupMask{1} << g;
    }
  }

  void record(int g, int lane, float t, float u, float v, std::uint32_t triangle, std::uint32_t instance) {
    group_[g].t_limit[lane] = t;
    limits_lowered_ |= GroupMask{1} << g;
    const std::size_t k = static_cast<std::size_t>(g) * kLanes + static_cast<std::size_t>(lane);
    out_.t[k] = t;
    out_.u[k] = u;
    out_.v[k] = v;
    out_.triangle[k] = triangle;
    out_.instance[k] = instance;
  }

  void retire(int g, int lane) {
    blocked_[g] |= 1u << lane;
    live_[g] &= ~(1u << lane);
    if (live_[g] == 0) alive_groups_ &= ~(GroupMask{1} << g);
  }

  PacketHits out_{};
  int groups_ = 0;
  std::array<Group, kMaxPacketGroups> group_;
  std::array<VisitGroup, kMaxPacketGroups> visit_;
  std::array<std::array<WatertightRay, kLanes>, kTest == TriangleTest::kWatertight ? kMaxPacketGroups : 1>
      watertight_;
  std::array<std::uint32_t, kMaxPacketGroups> live_{};
  std::array<std::uint32_t, kMaxPacketGroups> valid_{};
  std::array<std::uint32_t, kMaxPacketGroups> blocked_{};
  GroupMask alive_groups_ = 0;
  GroupMask limits_lowered_ = 0;  // the groups that recorded a hit since the walk's limit last looked
  bool common_origin_ = false;    // every live lane starts at common_origin_at_
  Vec3 common_origin_at_{0.0f};
  TraversalCounters counters_;
};

}  // namespace sinew::rt::packet_lanes
