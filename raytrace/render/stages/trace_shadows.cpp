#include "raytrace/render/stages/tile_stages.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/stages/stage_support.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/cull/static_tiles.h"

namespace sinew::rt {

using namespace stages;

namespace {

// Shadow rays [i0, i1) (at most kMaxPacketGroups groups) as one packet,
// traced by `trace(rays, blocked, work)` (a large_packet.h query); each
// blocked ray clears bit l of its pixel. Returns how many were blocked.
template <class Trace>
std::uint64_t occlude_run(std::size_t i0, std::size_t i1, int l, TileScratch& s, TraversalCounters& counters,
                          Trace&& trace) {
  static const std::vector<float> zeros(kMaxPacketGroups * kBlockLanes, 0.0f);
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  std::array<std::uint8_t, kMaxPacketGroups> active{}, blocked{};
  for (std::size_t i = i0; i < i1; i += kBlockLanes) {
    const std::size_t n = std::min<std::size_t>(kBlockLanes, i1 - i);
    active[(i - i0) / kBlockLanes] = static_cast<std::uint8_t>((1u << n) - 1u);
  }
  LargePacketRays rays;
  rays.groups = static_cast<int>((i1 - i0 + kBlockLanes - 1) / kBlockLanes);
  rays.o[0] = &s.so_x[i0];
  rays.o[1] = &s.so_y[i0];
  rays.o[2] = &s.so_z[i0];
  rays.d[0] = &s.sd_x[i0];
  rays.d[1] = &s.sd_y[i0];
  rays.d[2] = &s.sd_z[i0];
  rays.t_min = zeros.data();
  rays.t_max = &s.s_tmax[i0];
  rays.active = active.data();
  rays.group_frusta = s.plan.shadow_group_frusta;
  rays.clip_leaf_lanes = s.plan.clip_leaf_lanes;
  TraversalCounters work;
  trace(rays, blocked.data(), work);
  add_work(counters, work);
  std::uint64_t blocked_count = 0;
  for (int g = 0; g < rays.groups; ++g) {
    for (std::uint32_t m = blocked[static_cast<std::size_t>(g)] & active[static_cast<std::size_t>(g)]; m != 0;
         m &= m - 1) {
      const std::size_t i = i0 + static_cast<std::size_t>(g) * kBlockLanes + static_cast<std::size_t>(std::countr_zero(m));
      s.lit[s.shadow_pixel[i]] &= dark;
      ++blocked_count;
    }
  }
  return blocked_count;
}

// One large packet per region's run of shadow rays.
std::uint64_t trace_shadow_large(const Scene& scene, TriangleTest test, const std::vector<std::uint32_t>& objects,
                                 int l, TileScratch& s, TraversalCounters& counters) {
  std::uint64_t blocked_count = 0;
  for (std::size_t r = 0; r + 1 < s.shadow_region_begin.size(); ++r) {
    const std::size_t i0 = s.shadow_region_begin[r], i1 = s.shadow_region_begin[r + 1];
    counters.rays += i1 - i0;
    if (objects.empty()) continue;
    blocked_count += occlude_run(i0, i1, l, s, counters,
                                 [&](const LargePacketRays& rays, std::uint8_t* blocked, TraversalCounters& work) {
                                   occluded_large_packet(scene, rays, test, objects, blocked, &work);
                                 });
  }
  return blocked_count;
}

}  // namespace

std::uint64_t trace_shadow_rays(const Scene& scene, TriangleTest test, int l, TileScratch& s,
                                TraversalCounters& counters) {
  const int packet_rays = s.plan.packet_rays;
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  std::uint64_t blocked_count = 0;
  const auto block = [&](std::size_t i) {
    s.lit[s.shadow_pixel[i]] &= dark;
    ++blocked_count;
  };
  if (packet_rays <= 1) {
    offset_shadow_rays(s);
    compact_shadow_rays(s);
    for (std::size_t i = 0; i < s.shadow_count; ++i) {
      if (occluded(scene, s.shadow_ray(i), s.plan.shadow_mask, test, &counters)) block(i);
    }
    return blocked_count;
  }
  if (s.shadow_placed == 0) return 0;
  static const float kZeros[kPacketSize] = {};
  CullLists& lists = cull_lists();
  lists.tile.clear();
  RayBound tile_bound;
  if (s.shadows_aimed_only) {
    // Every ray the ends' box allows, as one bound: from the light to the
    // box, or from the box along the light. Per axis that is the same
    // range of directions (or origins) as the placed rays' own (the box's
    // faces are their extreme ends, grown, and rounded differences keep
    // their order), so the rays are placed only when it reaches an object:
    // a tile in the open places none.
    alignas(32) float o[3][kPacketSize] = {}, d[3][kPacketSize] = {};
    alignas(32) float t_min[kPacketSize] = {}, t_max[kPacketSize] = {};
    const Vec3 corners[2] = {s.shadow_ends.lower, s.shadow_ends.upper};
    for (int c = 0; c < 2; ++c) {
      for (int a = 0; a < 3; ++a) {
        o[a][c] = s.shadows_from_point ? s.shadow_origin[a] : corners[c][a];
        d[a][c] = s.shadows_from_point ? corners[c][a] - s.shadow_origin[a] : s.shadow_direction[a];
      }
      t_max[c] = s.shadows_from_point ? 1.0f : kInf;
    }
    const float* const origins[3] = {o[0], o[1], o[2]};
    const float* const directions[3] = {d[0], d[1], d[2]};
    tile_bound.add_lanes(origins, directions, t_min, t_max, 0b11u);
  } else {
    // The tile's rays bounded as placed, lane by lane (the same rays, so
    // the same bound as over the compacted ones).
    const float* const placed[3] = {s.shadow_lane_x.data(), s.shadow_lane_y.data(), s.shadow_lane_z.data()};
    if (s.shadows_per_lane) {
      alignas(32) float t_max[kPacketSize];
      std::fill_n(t_max, kPacketSize, s.shadow_tmax);
      for (std::size_t b = 0; b < s.blocks(); ++b) {
        if (s.shadow_lanes[b] == 0) continue;
        const std::size_t k0 = b * kBlockLanes;
        const float* const o[3] = {&s.shadow_from_x[k0], &s.shadow_from_y[k0], &s.shadow_from_z[k0]};
        const float* const d[3] = {placed[0] + k0, placed[1] + k0, placed[2] + k0};
        tile_bound.add_lanes(o, d, kZeros, t_max, s.shadow_lanes[b]);
      }
    } else if (s.shadows_from_point) {
      tile_bound.add_groups(s.shadow_origin, placed, 0.0f, 1.0f, std::span(s.shadow_lanes.data(), s.blocks()));
    } else {
      alignas(32) float d[3][kPacketSize], t_max[kPacketSize];
      for (int lane = 0; lane < kPacketSize; ++lane) {
        for (int a = 0; a < 3; ++a) d[a][lane] = s.shadow_direction[a];
        t_max[lane] = kInf;
      }
      const float* const directions[3] = {d[0], d[1], d[2]};
      for (std::size_t b = 0; b < s.blocks(); ++b) {
        if (s.shadow_lanes[b] == 0) continue;
        const std::size_t k0 = b * kBlockLanes;
        const float* const o[3] = {placed[0] + k0, placed[1] + k0, placed[2] + k0};
        tile_bound.add_lanes(o, directions, kZeros, t_max, s.shadow_lanes[b]);
      }
    }
  }
  // A tile whose rays can reach nothing (a ground in the open, mostly)
  // places and compacts none.
  cull_objects(scene, tile_bound, lists.tile, 0.0f, s.plan.shadow_mask);
  if (lists.tile.empty()) {
    counters.rays += s.shadow_placed;
    return 0;
  }
  offset_shadow_rays(s);
  compact_shadow_rays(s);
  // Pad a group past the last ray (inactive lanes, but the arithmetic
  // reads them; a large packet's groups start anywhere).
  for (std::size_t i = s.shadow_count; i < s.shadow_count + kPacketSize; ++i) {
    s.so_x[i] = s.so_y[i] = s.so_z[i] = 0.0f;
    s.sd_x[i] = s.sd_y[i] = 0.0f;
    s.sd_z[i] = 1.0f;
    s.s_tmax[i] = 1.0f;
  }
  thread_local StaticTile statics;
  if (gather_static_tile(scene, test, tile_bound, 0.0f, lists.tile, statics, shadow_tile_cone(s))) {
    counters.rays += s.shadow_count;
    return occluded_static_tile(statics, l, s, counters);
  }
  return trace_shadow_large(scene, test, lists.tile, l, s, counters);
}

std::uint64_t occluded_static_tile(const StaticTile& tile, int l, TileScratch& s, TraversalCounters& counters) {
  std::uint64_t blocked_count = 0;
  constexpr std::size_t kPacketLanes = kMaxPacketGroups * kBlockLanes;
  for (std::size_t i0 = 0; i0 < s.shadow_count; i0 += kPacketLanes) {
    const std::size_t i1 = std::min(s.shadow_count, i0 + kPacketLanes);
    blocked_count += occlude_run(i0, i1, l, s, counters,
                                 [&](const LargePacketRays& rays, std::uint8_t* blocked, TraversalCounters& work) {
                                   occluded_large_packet(rays, tile, blocked, &work);
                                 });
  }
  return blocked_count;
}

}  // namespace sinew::rt
