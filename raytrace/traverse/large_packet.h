// The packet core: one to 64 groups of eight rays (a tile's 4x2-pixel
// block, or its 8x8-, 16x16- or 32x16-pixel region) walk every tree once
// together; an 8-ray packet (traverse/packet_traversal.h) is one group. Cells
// are culled by an interval bound over the rays, carried into each bone's
// frame and grown by a bound on the single ray's slack, so a lane reaches
// every cell its single ray reaches; rays from one apex (a camera, a point
// light), and segments that start close together (an area light's
// samples), also cull leaf triangles by group frusta. The triangle tests are the
// single ray's, so each lane's nearest hit has its t, u and v; the triangle
// can differ only at an exact tie in t. docs/RAYTRACE.md, "Packets: the one
// core".
#pragma once

#include <cstdint>
#include <span>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/packet_traversal.h"
#include "raytrace/traverse/traversal.h"

namespace sinew::rt {

struct StaticTile;

inline constexpr int kMaxPacketGroups = 64;  // 512 rays: a 32x16-pixel region
// A set of a packet's groups, bit g for group g.
using GroupMask = std::uint64_t;
static_assert(kMaxPacketGroups <= 64, "a GroupMask holds one bit per group");

// A large packet's rays in place: 8 * groups lanes, every array contiguous
// over them (unaligned is fine). Lanes whose bit in `active[group]` is 0 are
// ignored but must hold finite values.
struct LargePacketRays {
  int groups = 0;  // 1 to kMaxPacketGroups
  const float* o[3] = {};
  const float* d[3] = {};
  const float* t_min = nullptr;
  const float* t_max = nullptr;
  const std::uint8_t* active = nullptr;  // per group, bit i: lane i
  // Camera packets: the groups are blocks of a pixel grid, grid_columns per
  // row (row-major), their rays leaving the eye along grid_forward plus
  // multiples of grid_right and grid_up (cull/grid_frusta.h). 0: no grid.
  // The grid's planes come from the lanes' own slopes, so rays of another
  // shape are still bounded, only less tightly.
  int grid_columns = 0;
  Vec3 grid_forward{0.0f}, grid_right{0.0f}, grid_up{0.0f};
  // Rays from one apex with finite ends (shadow rays): each group culls
  // with its own frustum instead of its slab in the packet's basis, tighter
  // and dearer per triangle. It pays on pixel-sized triangles, where a
  // leaf's box leaves it a group or two (docs/RAYTRACE.md, "Leaf boxes").
  bool group_frusta = false;
  // Rays from one apex among pixel-sized triangles: at a bone tree's leaf
  // each group's lanes are clipped to the box of the leaf's current
  // triangles and only those test them. On coarse meshes the clip keeps
  // nearly every lane and costs more than it saves (docs/RAYTRACE.md, "Leaf
  // triangles eight at a time, lanes clipped to the leaf box").
  bool clip_leaf_lanes = false;
};

// The nearest hits of every active lane, written to 8 * groups entries of
// `out` (misses: t = inf, ids kInvalidId). `objects`: the top-level objects
// (indices into scene.top_level().objects()) the rays may enter, in any
// order; a superset is fine, the packet culls them again. Counters: rays,
// object visits and triangle tests per lane, node visits once per cell the
// packet fetches.
void intersect_large_packet(const Scene& scene, const LargePacketRays& rays, TriangleTest test,
                            std::span<const std::uint32_t> objects, PacketHits out, TraversalCounters* counters);

// Occlusion of every active lane: blocked[g] bit i = lane i of group g is
// blocked within [t_min, t_max).
void occluded_large_packet(const Scene& scene, const LargePacketRays& rays, TriangleTest test,
                           std::span<const std::uint32_t> objects, std::uint8_t* blocked,
                           TraversalCounters* counters);

// The same packets against a tile's few gathered static triangles
// (cull/static_tiles.h): every active lane tests each triangle in order,
// with no top level, no tree and no bound; the lane set-up, the triangle
// tests and the hits are the ones above (traverse/packet_rays.h). The fast
// test only, as gather_static_tile requires. Counters as above: object
// visits per lane and mesh entered, triangle tests per lane.
void intersect_large_packet(const LargePacketRays& rays, const StaticTile& tile, PacketHits out,
                            TraversalCounters* counters);
void occluded_large_packet(const LargePacketRays& rays, const StaticTile& tile, std::uint8_t* blocked,
                           TraversalCounters* counters);

}  // namespace sinew::rt
