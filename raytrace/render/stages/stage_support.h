// Pieces the tile stages (render/stages/tile_stages.h) share: lane loads and
// stores over the tile's arrays, the rounding bound, a missed lane, and the
// per-thread list of a tile's culled objects. Private to render/stages.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/cull/ray_bound.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/math/float8.h"

namespace sinew::rt::stages {

inline constexpr float kInf = std::numeric_limits<float>::infinity();

// pbrt's gamma(n): a bound on n successive float roundings.
inline constexpr float gamma(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (static_cast<float>(n) * u) / (1.0f - static_cast<float>(n) * u);
}

inline Vec3x8 load3(const std::vector<float>& x, const std::vector<float>& y, const std::vector<float>& z, std::size_t k) {
  return {Float8::load(&x[k]), Float8::load(&y[k]), Float8::load(&z[k])};
}
inline void store3(const Vec3x8& v, std::vector<float>& x, std::vector<float>& y, std::vector<float>& z, std::size_t k) {
  v.x.store(&x[k]);
  v.y.store(&y[k]);
  v.z.store(&z[k]);
}

// offset_origin's push of block k0's hits along their camera-facing
// normal, by the position's rounding bound: the offset to add.
inline Vec3x8 surface_push(const TileScratch& s, std::size_t k0, Float8 e) {
  const Vec3x8 facing = load3(s.gx, s.gy, s.gz, k0);
  const Float8 distance = abs(facing.x) * e + abs(facing.y) * e + abs(facing.z) * e;
  return distance * facing;
}
inline Vec3x8 surface_push(const TileScratch& s, std::size_t k0) {
  return surface_push(s, k0, Float8::load(&s.error[k0]));
}
// The same for rays that run from a point `from` (a light's, of largest
// |coordinate| `magnitude`) to the hits: shadow_ray_from_light's wider
// bound, which also covers the rounding of from - hit.
// `further`: a distance added to the bound (slack_clearance below).
inline Vec3x8 surface_push_from(const TileScratch& s, std::size_t k0, const Vec3x8& from, Float8 magnitude,
                                Float8 further = Float8(0.0f)) {
  const Vec3x8 to = from - load3(s.px, s.py, s.pz, k0);
  const Float8 reach = magnitude + Float8(2.0f) * max(max(abs(to.x), abs(to.y)), abs(to.z));
  return surface_push(s, k0, Float8::load(&s.error[k0]) + Float8(gamma(32)) * reach + further);
}

// A further push for segment rays (an area light's samples, ambient
// occlusion) that clears the traversal's slack around world boxes: over
// any of them it is at most 2^-21 (|o| + t |d| + |box|), grown by 1%
// (traverse/ray_frames.h world_slack, cull/ray_bound.h
// traversal_slack_bound), and here |o|, |box| <= s.scene_magnitude and
// t |d| <= `reach` (the segment's length from the hit; the scene's
// magnitude for unbounded rays). Twice that, added to the rounding bound,
// puts a segment that leaves a flat box (a ground, a wall: its box is its
// plane) on the box's outer side by more than any slack grows it, so
// neither the tile's bound nor a packet enters the box, while a hit on it
// is as impossible as before.
inline Float8 slack_clearance(const TileScratch& s, Float8 reach) {
  return Float8(0x1.0p-20f) * (Float8(2.0f * s.scene_magnitude) + reach);
}

// Bit i: bit l of lit[i], for eight bytes (each lane's bit gathered into
// the top byte by one multiply: no two partial products overlap).
inline std::uint32_t lane_bits(const std::uint8_t* lit, int l) {
  std::uint64_t word;
  std::memcpy(&word, lit, sizeof word);
  return static_cast<std::uint32_t>((((word >> l) & 0x0101010101010101ull) * 0x0102040810204080ull) >> 56);
}

// Per-thread list of the objects a tile's rays may enter.
struct CullLists {
  std::vector<std::uint32_t> tile;
};
inline CullLists& cull_lists() {
  thread_local CullLists lists;
  return lists;
}

// A packet query's work added to the tile's (rays are counted by the caller).
inline void add_work(TraversalCounters& into, const TraversalCounters& from) { into += from.for_rays(0); }

inline void set_miss(TileScratch& s, std::size_t k) {
  s.t[k] = kInf;
  s.u[k] = 0.0f;
  s.v[k] = 0.0f;
  s.triangle[k] = kInvalidId;
  s.instance[k] = kInvalidId;
}

}  // namespace sinew::rt::stages
