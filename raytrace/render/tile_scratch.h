// One tile's working set, structure of arrays, reused by each thread across
// tiles and frames. The tile's pixels are laid out in blocks of 4x2 (eight
// lanes: one ray packet, one Float8): pixel k = 8 * block + lane, lane =
// 4 * (y % 2) + x % 4, blocks row-major over the tile. Every stage
// (render/tile_stages.h) walks the blocks, so the rays, hits and surfaces of
// a block stay in cache from ray generation through the shadow rays to the
// shading. Shared by the renderer and by tracers that stand in for it (the
// Embree peer of the benchmarks), which run the same stages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/jobs/job_system.h"

namespace sinew::rt {

inline constexpr int kBlockWidth = 4;
inline constexpr int kBlockHeight = 2;
inline constexpr int kBlockLanes = kBlockWidth * kBlockHeight;

struct TileScratch {
  Tile tile;
  int blocks_x = 0;
  int blocks_y = 0;
  std::size_t lanes = 0;  // 8 * blocks

  std::vector<std::uint8_t> block_pixels;  // per block: bit i set when lane i is a pixel of the image
  std::vector<std::uint8_t> block_hits;    // per block: bit i set when lane i hit
  // Primary rays: unit directions (the origin is the camera's eye).
  std::vector<float> dir_x, dir_y, dir_z;
  // Nearest hits (triangle kInvalidId on a miss).
  std::vector<float> t, u, v;
  std::vector<std::uint32_t> triangle, instance;
  // Surfaces at the hits, world space (render/renderer.h SurfacePoint).
  std::vector<float> px, py, pz;     // position
  std::vector<float> gx, gy, gz;     // unit geometric normal
  std::vector<float> nx, ny, nz;     // unit shading normal facing the camera
  std::vector<float> ar, ag, ab;     // albedo
  std::vector<float> error;          // rounding bound of the position, every axis
  std::vector<std::uint8_t> lit;     // bit l: light l reaches the hit
  // This light's shadow rays, compacted in block order (render/tile_stages.h).
  std::size_t shadow_count = 0;
  std::vector<std::uint32_t> shadow_pixel;  // the lane index k each ray belongs to
  std::vector<float> so_x, so_y, so_z, sd_x, sd_y, sd_z, s_tmax;

  // Lays out `t`'s pixels and sizes every array (padded to whole packets).
  void prepare(const Tile& area);

  int pixel_x(std::size_t k) const {
    const std::size_t block = k / kBlockLanes;
    return tile.x0 + static_cast<int>(block % static_cast<std::size_t>(blocks_x)) * kBlockWidth +
           static_cast<int>(k % kBlockWidth);
  }
  int pixel_y(std::size_t k) const {
    const std::size_t block = k / kBlockLanes;
    return tile.y0 + static_cast<int>(block / static_cast<std::size_t>(blocks_x)) * kBlockHeight +
           static_cast<int>((k % kBlockLanes) / kBlockWidth);
  }
  bool is_pixel(std::size_t k) const { return (block_pixels[k / kBlockLanes] >> (k % kBlockLanes) & 1u) != 0; }
  bool hit(std::size_t k) const { return (block_hits[k / kBlockLanes] >> (k % kBlockLanes) & 1u) != 0; }

 private:
  std::size_t capacity_ = 0;  // lanes every array holds
};

// The calling thread's scratch. One tile at a time per thread: a tile's
// work never starts another tile's on the same thread.
inline TileScratch& tile_scratch() {
  thread_local TileScratch scratch;
  return scratch;
}

}  // namespace sinew::rt
