// Tiles whose rays can reach only a few triangles of static meshes: a
// ground, a checkered floor, walls. Most of a frame's pixels are such
// pixels, and their shadow rays too. The tile's triangles are gathered once
// from the tile's bound (small meshes whole, larger ones from the cells of
// their kd-tree the bound reaches), and every ray of the tile is tested
// against them directly, eight lanes at a time: no packet bound, no tree
// walk per packet, no box clip, and a triangle's per-origin terms once per
// tile for the camera's rays.
//
// Culling is conservative as in render/ray_bound.h: a triangle is left out
// only when no ray of the tile can enter its box grown by the traversal's
// slack bound, so each lane's nearest hit is the single ray's; between two
// triangles hit at exactly the same t the one gathered first wins (meshes in
// list order, each mesh's triangles in ascending order, as the single ray
// meets them in a leaf).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/render/ray_bound.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/render/traversal.h"
#include "raytrace/scene/scene.h"

namespace sinew::rt {

// At most this many triangles per tile take the direct tests: each costs
// every ray of the tile a share of an eight-lane test. On the demo's floor
// (536 triangles) limits from 16 to 48 measure alike and 8 is slower
// (docs/RAYTRACE.md); 24 holds a box and the floor quads around it.
inline constexpr std::size_t kMaxStaticTileTriangles = 24;

struct StaticTriangle {
  Vec3 p0, p1, p2;
  std::uint32_t triangle;
  std::uint32_t instance;
  bool zero_area;  // never hit (the scalar test's last check, once per triangle)
  bool first;      // the first of its mesh: the rays enter a new object
};

// The triangles of one tile (per thread, reused).
struct StaticTile {
  std::vector<StaticTriangle> triangles;
  std::uint64_t meshes = 0;  // the static meshes they came from
};

// Gathers into `tile` the triangles that some ray of `bound` may reach
// among `objects` (indices into scene.top_level().objects()), every box
// grown by `extra_grow` beyond the bound's slack bound as cull_objects
// grows it. Returns whether the direct tests apply: the fast triangle test,
// a non-empty list of static meshes only, and at most
// kMaxStaticTileTriangles triangles reached.
bool gather_static_tile(const Scene& scene, TriangleTest test, const RayBound& bound, float extra_grow,
                        std::span<const std::uint32_t> objects, StaticTile& tile);

// The nearest hits of the tile's camera rays (from `eye` along s.dir_*)
// among the gathered triangles: fills t, u, v, triangle, instance and
// block_hits as trace_primary does (render/tile_stages.h). Counts object
// visits and triangle tests, not rays.
void intersect_static_tile(const StaticTile& tile, const Vec3& eye, TileScratch& s, TraversalCounters& counters);

// Occlusion of the tile's shadow rays for light l (s.so_*, s.sd_*, t in
// [0, s.s_tmax)) by the gathered triangles: a blocked ray clears bit l of
// its pixel's s.lit, as trace_shadow_rays does. Returns how many were
// blocked. Counts object visits and triangle tests, not rays.
std::uint64_t occluded_static_tile(const StaticTile& tile, int l, TileScratch& s, TraversalCounters& counters);

}  // namespace sinew::rt
