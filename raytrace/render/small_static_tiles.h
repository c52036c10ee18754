// Tiles whose rays can reach only small static meshes (a ground quad, a
// wall: render/traversal_shared.h is_small_static). Most of a frame's
// pixels are such ground or wall pixels, and their shadow rays too. Every
// ray of the tile is tested against the meshes' few triangles directly,
// eight lanes at a time: no packet bound, no box clip, and a triangle's
// per-origin terms once per tile for the camera's rays.
//
// Each lane sees the same triangle tests in the same order as the large
// packets' own short cut for such meshes (render/large_packet.cpp), so the
// hits are the same; between two meshes hit at exactly the same t the one
// listed first wins.
#pragma once

#include <cstdint>
#include <span>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/render/traversal.h"
#include "raytrace/scene/scene.h"

namespace sinew::rt {

// Whether the short cut applies: the fast triangle test, an AVX2 build,
// and every object of `objects` (indices into scene.top_level().objects())
// a small static mesh. An empty list does not qualify.
bool small_statics_tile(const Scene& scene, TriangleTest test, std::span<const std::uint32_t> objects);

// The nearest hits of the tile's camera rays (from `eye` along s.dir_*)
// among `objects`: fills t, u, v, triangle, instance and block_hits as
// trace_primary does (render/tile_stages.h). Counts object visits and
// triangle tests, not rays.
void intersect_small_statics_tile(const Scene& scene, const Vec3& eye, std::span<const std::uint32_t> objects,
                                  TileScratch& s, TraversalCounters& counters);

// Occlusion of the tile's shadow rays for light l (s.so_*, s.sd_*, t in
// [0, s.s_tmax)) by `objects`: a blocked ray clears bit l of its pixel's
// s.lit, as trace_shadow_rays does. Returns how many were blocked. Counts
// object visits and triangle tests, not rays.
std::uint64_t occluded_small_statics_tile(const Scene& scene, std::span<const std::uint32_t> objects, int l,
                                          TileScratch& s, TraversalCounters& counters);

}  // namespace sinew::rt
