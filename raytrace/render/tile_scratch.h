// One tile's working set, structure of arrays, reused by each thread across
// tiles and frames. Pixels are laid out in blocks of 4x2 (eight lanes: one
// ray group), pixel k = 8 * block + lane, lane = 4 * (y % 2) + x % 4; blocks
// are grouped into regions (a large packet's 8x8, 16x16 or 32x16 pixels, or
// one block each), regions row-major over the tile and blocks row-major
// within a region, so a region's rays and hits are consecutive. Every stage
// (render/stages/tile_stages.h) walks the blocks, so a block's data stays in
// cache from ray generation to shading. Shared with tracers that run the same
// stages (the Embree peer of the benchmarks).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "raytrace/render/output/output_staging.h"
#include "raytrace/render/trace_plan.h"
#include "runtime/jobs/job_system.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"

namespace sinew::rt {

inline constexpr int kBlockWidth = 4;
inline constexpr int kBlockHeight = 2;
inline constexpr int kBlockLanes = kBlockWidth * kBlockHeight;

struct TileScratch {
  Tile tile;
  int blocks_x = 0;
  int blocks_y = 0;
  std::size_t lanes = 0;  // 8 * blocks

  // Region r holds blocks [region_begin[r], region_begin[r + 1]).
  std::vector<std::uint32_t> region_begin;
  std::vector<int> block_dx, block_dy;     // per block: its top-left pixel, from the tile's
  std::vector<std::uint8_t> block_pixels;  // per block: bit i set when lane i is a pixel of the image
  std::vector<std::uint8_t> block_hits;    // per block: bit i set when lane i hit
  // Per block: bit i set when lane i hit a character (not a static mesh);
  // set with the surfaces (reconstruct_surfaces).
  std::vector<std::uint8_t> block_on_character;
  // Primary rays: unit directions (the origin is the camera's eye).
  std::vector<float> dir_x, dir_y, dir_z;
  // Nearest hits (triangle kInvalidId on a miss).
  std::vector<float> t, u, v;
  std::vector<std::uint32_t> triangle, instance;
  // Surfaces at the hits, world space (render/surface.h SurfacePoint).
  std::vector<float> px, py, pz;     // position
  std::vector<float> gx, gy, gz;     // unit geometric normal
  std::vector<float> nx, ny, nz;     // unit shading normal facing the camera
  std::vector<float> ar, ag, ab;     // albedo
  std::vector<float> error;          // rounding bound of the position, every axis
  // The largest |coordinate| of the scene's top level this frame, 0 when it
  // is empty (reconstruct_surfaces; a host's surfaces): segment rays leave
  // their surfaces clear of the traversal's slack by it (render/stages/stage_support.h
  // slack_clearance).
  float scene_magnitude = 0.0f;
  // The hit's texture coordinates and material, when an output asks for
  // them (SurfaceSettings::hit_attributes): 0 without uvs, kInvalidId
  // without a material.
  std::vector<float> uv_x, uv_y;
  std::vector<std::uint32_t> material;
  std::vector<std::uint8_t> lit;     // bit l: light l reaches the hit
  // A colour-only frame's shading (render/stages/tile_stages.h shade_and_write):
  // the linear colour of each hit, and its RGBA8 pixel, encoded sixteen
  // lanes at a time (render/output/srgb_encode.h).
  std::vector<float> lr, lg, lb;
  std::vector<std::uint32_t> rgba8;
  // This light's shadow rays as placed, lane by lane (render/stages/tile_stages.h
  // place_shadow_rays): per block the lanes with a ray, and per lane the
  // ray's direction (a point light's, from shadow_origin) or its origin (a
  // directional light's, along shadow_direction).
  std::size_t shadow_placed = 0;
  std::vector<std::uint8_t> shadow_lanes;
  std::vector<float> shadow_lane_x, shadow_lane_y, shadow_lane_z;
  std::vector<float> shadow_push_x, shadow_push_y, shadow_push_z;
  Vec3 shadow_direction{0.0f};
  // Aimed but not placed yet (render/stages/tile_stages.h aim_shadow_rays): the
  // lanes are chosen, shadow_lane_* hold the pushed-off points and
  // shadow_push_* the pushes, which placing turns into the rays.
  bool shadows_aimed_only = false;
  // Aimed rays' ends (a point light's rays' far ends, a directional light's
  // origins) all lie inside; empty after place_shadow_rays, which bounds
  // nothing.
  Aabb shadow_ends;
  bool shadows_compacted = true;  // shadow_* below hold the placed rays
  // This light's shadow rays, compacted in block order (render/stages/tile_stages.h
  // compact_shadow_rays).
  std::size_t shadow_count = 0;
  std::vector<std::uint32_t> shadow_pixel;  // the lane index k each ray belongs to
  std::vector<float> so_x, so_y, so_z, sd_x, sd_y, sd_z, s_tmax;
  // Whether every shadow ray starts at shadow_origin with t in [0, 1) (a
  // point light's: render/surface.h shadow_ray_from_light).
  bool shadows_from_point = false;
  Vec3 shadow_origin{0.0f};
  // Whether the rays are segments, each from its own origin
  // (shadow_from_*) along its own direction (shadow_lane_*) with t in
  // [0, shadow_tmax): an area light's samples and ambient occlusion rays
  // (render/stages/tile_stages.h place_light_samples, place_ao_rays).
  bool shadows_per_lane = false;
  // Whether those segments start at points of a light, few of them shared
  // by many rays (an area light's samples: render/stages/sample_rays.cpp),
  // so that compaction splits runs by origin.
  bool segments_share_origins = false;
  std::vector<std::uint8_t> segments_pending;  // per block, compaction's lanes not yet in a run
  float shadow_tmax = 1.0f;
  std::vector<float> shadow_from_x, shadow_from_y, shadow_from_z;
  // Each pixel's shift of one stream's sample pattern (shift_pixels).
  std::vector<float> shift_xi, shift_eta, shift_cos, shift_sin;
  // Per area light l, lanes [l * lanes, (l + 1) * lanes): the fraction of
  // its samples that reach the hit; and per hit the fraction of ambient
  // occlusion rays that escape.
  std::vector<float> light_fraction;
  std::vector<float> ao_open;
  // Shadow run r: rays [shadow_region_begin[r], shadow_region_begin[r + 1])
  // come from one region's pixels, those on characters or those on static
  // meshes (runs without a ray have no entry), split finer where the plan
  // says so (TracePlan::split_fine_shadows, split_static_shadows); segment
  // rays' runs are one sample class's instead (compact_shadow_rays).
  std::vector<std::uint32_t> shadow_region_begin;
  // How this frame traces (render/trace_plan.h); set by prepare.
  TracePlan plan;
  // The tile's outputs until shade_and_write stores them (render/output/output_staging.h).
  OutputStaging staging;

  // Keeps `frame_plan` and lays out `area`'s pixels in its regions of
  // region_blocks_x by region_blocks_y blocks (clipped at the tile's edges);
  // sizes every array (padded to whole groups, plus one group of slack for
  // the shadow rays' unaligned groups, and the sRGB encoding's pairs of
  // blocks).
  void prepare(const Tile& area, const TracePlan& frame_plan = {});

  std::size_t blocks() const { return lanes / kBlockLanes; }
  std::size_t regions() const { return region_begin.empty() ? 0 : region_begin.size() - 1; }
  // Region r's blocks are row-major: its width in blocks is its first row's.
  std::size_t region_columns(std::size_t r) const {
    const std::size_t b0 = region_begin[r], b1 = region_begin[r + 1];
    std::size_t columns = 0;
    while (b0 + columns < b1 && block_dy[b0 + columns] == block_dy[b0]) ++columns;
    return columns;
  }
  int block_x0(std::size_t b) const { return tile.x0 + block_dx[b]; }
  int block_y0(std::size_t b) const { return tile.y0 + block_dy[b]; }
  int pixel_x(std::size_t k) const { return block_x0(k / kBlockLanes) + static_cast<int>(k % kBlockWidth); }
  int pixel_y(std::size_t k) const {
    return block_y0(k / kBlockLanes) + static_cast<int>((k % kBlockLanes) / kBlockWidth);
  }
  bool is_pixel(std::size_t k) const { return (block_pixels[k / kBlockLanes] >> (k % kBlockLanes) & 1u) != 0; }
  bool hit(std::size_t k) const { return (block_hits[k / kBlockLanes] >> (k % kBlockLanes) & 1u) != 0; }
  // Shadow ray i as a single ray: o + t d, t in [0, s_tmax).
  Ray shadow_ray(std::size_t i) const {
    Ray ray;
    ray.origin = Vec3(so_x[i], so_y[i], so_z[i]);
    ray.direction = Vec3(sd_x[i], sd_y[i], sd_z[i]);
    ray.t_min = 0.0f;
    ray.t_max = s_tmax[i];
    return ray;
  }

 private:
  std::size_t capacity_ = 0;  // lanes every array holds
  // The layout last made: a tile of the same size and regions (most tiles
  // of a frame) reuses it wherever it lies.
  int layout_width_ = -1, layout_height_ = -1, layout_region_x_ = -1, layout_region_y_ = -1;
};

// The calling thread's scratch. One tile at a time per thread: a tile's
// work never starts another tile's on the same thread.
inline TileScratch& tile_scratch() {
  thread_local TileScratch scratch;
  return scratch;
}

}  // namespace sinew::rt
