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

// Ray arrays every large packet of primary rays shares: the eye, t in [0, inf).
struct PrimaryLanes {
  alignas(32) float o[3][kMaxPacketGroups * kBlockLanes];
  alignas(32) float t_min[kMaxPacketGroups * kBlockLanes];
  alignas(32) float t_max[kMaxPacketGroups * kBlockLanes];
  Vec3 eye{std::numeric_limits<float>::quiet_NaN()};
  PrimaryLanes() {
    std::fill(std::begin(t_min), std::end(t_min), 0.0f);
    std::fill(std::begin(t_max), std::end(t_max), kInf);
  }
  void set_eye(const Vec3& e) {
    if (e.x == eye.x && e.y == eye.y && e.z == eye.z) return;
    eye = e;
    for (int a = 0; a < 3; ++a) std::fill(std::begin(o[a]), std::end(o[a]), e[a]);
  }
};

// The hits of blocks [b0, b1) (at most kMaxPacketGroups) as one packet,
// traced by `trace(rays, hits, work)` (a large_packet.h query); block_hits
// set from the triangle ids. `grid_columns`: the blocks' pixel grid
// (LargePacketRays), 0 for none.
template <class Trace>
void trace_blocks(const PinholeCamera& camera, std::size_t b0, std::size_t b1, std::size_t grid_columns,
                  TileScratch& s, TraversalCounters& counters, Trace&& trace) {
  thread_local PrimaryLanes shared;
  shared.set_eye(camera.eye());
  const std::size_t k0 = b0 * kBlockLanes;
  LargePacketRays rays;
  rays.groups = static_cast<int>(b1 - b0);
  for (int a = 0; a < 3; ++a) rays.o[a] = shared.o[a];
  rays.d[0] = &s.dir_x[k0];
  rays.d[1] = &s.dir_y[k0];
  rays.d[2] = &s.dir_z[k0];
  rays.t_min = shared.t_min;
  rays.t_max = shared.t_max;
  rays.active = &s.block_pixels[b0];
  rays.grid_columns = static_cast<int>(grid_columns);
  rays.grid_forward = camera.forward();
  rays.grid_right = camera.right();
  rays.grid_up = camera.up();
  rays.clip_leaf_lanes = s.plan.clip_leaf_lanes;
  const PacketHits hits{&s.t[k0], &s.u[k0], &s.v[k0], &s.triangle[k0], &s.instance[k0]};
  TraversalCounters work;
  trace(rays, hits, work);
  add_work(counters, work);
  for (std::size_t b = b0; b < b1; ++b) {
    std::uint32_t hit_bits = 0;
    for (int lane = 0; lane < kBlockLanes; ++lane) {
      hit_bits |= s.triangle[b * kBlockLanes + static_cast<std::size_t>(lane)] != kInvalidId ? (1u << lane) : 0u;
    }
    s.block_hits[b] = static_cast<std::uint8_t>(hit_bits & s.block_pixels[b]);
  }
}

// One large packet per region: its blocks are consecutive in `s`.
void trace_primary_large(const Scene& scene, const PinholeCamera& camera, TriangleTest test,
                         const std::vector<std::uint32_t>& objects, TileScratch& s, TraversalCounters& counters) {
  for (std::size_t r = 0; r < s.regions(); ++r) {
    const std::size_t b0 = s.region_begin[r], b1 = s.region_begin[r + 1];
    for (std::size_t b = b0; b < b1; ++b) counters.rays += static_cast<std::uint64_t>(std::popcount(s.block_pixels[b]));
    if (objects.empty()) {
      for (std::size_t k = b0 * kBlockLanes; k < b1 * kBlockLanes; ++k) set_miss(s, k);
      for (std::size_t b = b0; b < b1; ++b) s.block_hits[b] = 0;
      continue;
    }
    trace_blocks(camera, b0, b1, s.region_columns(r), s, counters,
                 [&](const LargePacketRays& rays, const PacketHits& hits, TraversalCounters& work) {
                   intersect_large_packet(scene, rays, test, objects, hits, &work);
                 });
  }
}

}  // namespace

void trace_primary(const Scene& scene, const PinholeCamera& camera, TriangleTest test, TileScratch& s,
                   TraversalCounters& counters) {
  const int packet_rays = s.plan.packet_rays;
  const std::size_t blocks = s.lanes / kBlockLanes;
  const Vec3 eye = camera.eye();
  if (packet_rays <= 1) {
    for (std::size_t b = 0; b < blocks; ++b) {
      std::uint32_t hits = 0;
      for (int lane = 0; lane < kBlockLanes; ++lane) {
        const std::size_t k = b * kBlockLanes + static_cast<std::size_t>(lane);
        if (!(s.block_pixels[b] >> lane & 1u)) {
          set_miss(s, k);
          continue;
        }
        Ray ray;
        ray.origin = eye;
        ray.direction = Vec3(s.dir_x[k], s.dir_y[k], s.dir_z[k]);
        const Hit hit = intersect(scene, ray, s.plan.camera_mask, test, &counters);
        s.t[k] = hit.t;
        s.u[k] = hit.u;
        s.v[k] = hit.v;
        s.triangle[k] = hit.triangle_id;
        s.instance[k] = hit.instance_id;
        hits |= hit.valid() ? (1u << lane) : 0u;
      }
      s.block_hits[b] = static_cast<std::uint8_t>(hits);
    }
    return;
  }
  // One bound over the whole tile picks the objects any of its rays may
  // enter; each packet culls them again with its own bound.
  CullLists& lists = cull_lists();
  lists.tile.clear();
  RayBound tile_bound;
  const float* const dirs[3] = {s.dir_x.data(), s.dir_y.data(), s.dir_z.data()};
  tile_bound.add_groups(eye, dirs, 0.0f, kInf, std::span<const std::uint8_t>(s.block_pixels.data(), blocks));
  cull_objects(scene, tile_bound, lists.tile, 0.0f, s.plan.camera_mask);
  thread_local StaticTile statics;
  if (gather_static_tile(scene, test, tile_bound, 0.0f, lists.tile, statics, camera_tile_cone(camera, s.tile))) {
    for (std::size_t b = 0; b < blocks; ++b) counters.rays += static_cast<std::uint64_t>(std::popcount(s.block_pixels[b]));
    intersect_static_tile(statics, camera, s, counters);
    return;
  }
  trace_primary_large(scene, camera, test, lists.tile, s, counters);
}

void intersect_static_tile(const StaticTile& tile, const PinholeCamera& camera, TileScratch& s,
                           TraversalCounters& counters) {
  // Packets of whole block rows: the core needs no grid here (no frusta).
  for (std::size_t b0 = 0; b0 < s.blocks(); b0 += kMaxPacketGroups) {
    const std::size_t b1 = std::min(s.blocks(), b0 + static_cast<std::size_t>(kMaxPacketGroups));
    trace_blocks(camera, b0, b1, 0, s, counters,
                 [&](const LargePacketRays& rays, const PacketHits& hits, TraversalCounters& work) {
                   intersect_large_packet(rays, tile, hits, &work);
                 });
  }
}

}  // namespace sinew::rt
