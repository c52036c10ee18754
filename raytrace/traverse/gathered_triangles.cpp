// The packet core against a tile's gathered static triangles
// (traverse/large_packet.h, the StaticTile overloads): the core's rays and
// triangle tests (traverse/packet_rays.h) without its walks.
#include <bit>
#include <cstdint>

#include "raytrace/cull/static_tiles.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/traverse/packet_rays.h"

namespace sinew::rt {
namespace {

using packet_lanes::for_each_bit;
using packet_lanes::PacketRays;
using packet_lanes::thread_query;

template <bool kAnyHit>
class GatheredQuery : public PacketRays<TriangleTest::kFast, kAnyHit> {
  using Rays = PacketRays<TriangleTest::kFast, kAnyHit>;
  using Rays::alive_groups_;
  using Rays::counters_;
  using Rays::live_;
  using Rays::test_groups;
  using Rays::visit_;

 public:
  // Every live lane against each triangle, in the tile's order (its ties
  // go to the first, as the single ray's do): a lane is never clipped, so
  // it tests every triangle its packet reaches. Closest hit: every lane
  // enters each of the tile's meshes; any hit: a lane enters a mesh when
  // it is still unblocked at its first triangle.
  void run(const StaticTile& tile) {
    for_each_bit(alive_groups_, [&](int g) { visit_[g].leaf_lanes = live_[g]; });
    if constexpr (!kAnyHit) counters_.object_visits += tile.meshes * live_lane_count();
    for (const StaticTriangle& tri : tile.triangles) {
      if (alive_groups_ == 0) return;
      if (kAnyHit && tri.first) counters_.object_visits += live_lane_count();
      test_groups(alive_groups_, tri.p0, tri.p1, tri.p2, tri.triangle, tri.instance);
    }
  }

 private:
  std::uint64_t live_lane_count() const {
    std::uint64_t n = 0;
    for_each_bit(alive_groups_, [&](int g) { n += static_cast<std::uint64_t>(std::popcount(live_[g])); });
    return n;
  }
};

template <bool kAnyHit>
void run_query(const LargePacketRays& rays, const StaticTile& tile, PacketHits out, std::uint8_t* blocked,
               TraversalCounters* counters) {
  GatheredQuery<kAnyHit>& query = thread_query<GatheredQuery<kAnyHit>>();
  query.start(rays, out);
  query.run(tile);
  query.finish(blocked, counters);
}

}  // namespace

void intersect_large_packet(const LargePacketRays& rays, const StaticTile& tile, PacketHits out,
                            TraversalCounters* counters) {
  run_query<false>(rays, tile, out, nullptr, counters);
}

void occluded_large_packet(const LargePacketRays& rays, const StaticTile& tile, std::uint8_t* blocked,
                           TraversalCounters* counters) {
  run_query<true>(rays, tile, PacketHits{nullptr, nullptr, nullptr, nullptr, nullptr}, blocked, counters);
}

}  // namespace sinew::rt
