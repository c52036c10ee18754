#include "raytrace/render/tile_scratch.h"

#include <algorithm>

#include "raytrace/render/output/srgb_encode.h"
#include "raytrace/render/render_settings.h"

namespace sinew::rt {

void TileScratch::prepare(const Tile& area, const TracePlan& frame_plan) {
  tile = area;
  plan = frame_plan;
  shadow_placed = 0;
  shadows_compacted = true;
  shadow_count = 0;
  shadow_region_begin.clear();
  shadows_from_point = false;
  shadows_per_lane = false;
  shadows_aimed_only = false;
  const int width = area.x1 - area.x0, height = area.y1 - area.y0;
  const int rx = std::max(1, plan.region_blocks_x), ry = std::max(1, plan.region_blocks_y);
  if (width == layout_width_ && height == layout_height_ && rx == layout_region_x_ && ry == layout_region_y_) {
    std::fill_n(block_hits.begin(), blocks(), std::uint8_t{0});
    std::fill_n(block_on_character.begin(), blocks(), std::uint8_t{0});
    return;
  }
  layout_width_ = width;
  layout_height_ = height;
  layout_region_x_ = rx;
  layout_region_y_ = ry;
  blocks_x = (width + kBlockWidth - 1) / kBlockWidth;
  blocks_y = (height + kBlockHeight - 1) / kBlockHeight;
  const std::size_t blocks = static_cast<std::size_t>(blocks_x) * static_cast<std::size_t>(blocks_y);
  lanes = blocks * kBlockLanes;
  if (block_pixels.size() < blocks) {
    block_pixels.resize(blocks);
    block_hits.resize(blocks);
    block_on_character.resize(blocks);
    shadow_lanes.resize(blocks);
    segments_pending.resize(blocks);
    block_dx.resize(blocks);
    block_dy.resize(blocks);
  }
  // One spare group: a region's shadow rays start anywhere in the compacted
  // arrays and are read a whole group at a time, and the sRGB encoding
  // reads and writes pairs of blocks.
  static_assert(kSrgbEncodeLanes == 2 * kBlockLanes);
  const std::size_t arrays = lanes + kBlockLanes;
  if (capacity_ < arrays) {
    for (std::vector<float>* a : {&dir_x, &dir_y, &dir_z, &t, &u, &v, &px, &py, &pz, &gx, &gy, &gz, &nx, &ny,
                                  &nz, &ar, &ag, &ab, &error, &so_x, &so_y, &so_z, &sd_x, &sd_y, &sd_z, &s_tmax,
                                  &shadow_lane_x, &shadow_lane_y, &shadow_lane_z, &shadow_push_x,
                                  &shadow_push_y, &shadow_push_z, &lr, &lg, &lb, &uv_x, &uv_y, &shadow_from_x,
                                  &shadow_from_y, &shadow_from_z, &shift_xi, &shift_eta, &shift_cos, &shift_sin,
                                  &ao_open}) {
      a->resize(arrays);
    }
    light_fraction.resize(arrays * kMaxLights);
    triangle.resize(arrays);
    instance.resize(arrays);
    material.resize(arrays);
    rgba8.resize(arrays);
    lit.resize(arrays);
    shadow_pixel.resize(arrays);
    capacity_ = arrays;
  }
  region_begin.clear();
  std::size_t b = 0;
  for (int y0 = 0; y0 < blocks_y; y0 += ry) {
    for (int x0 = 0; x0 < blocks_x; x0 += rx) {
      region_begin.push_back(static_cast<std::uint32_t>(b));
      for (int y = y0; y < std::min(blocks_y, y0 + ry); ++y) {
        for (int x = x0; x < std::min(blocks_x, x0 + rx); ++x, ++b) {
          const int dx = x * kBlockWidth;
          const int dy = y * kBlockHeight;
          block_dx[b] = dx;
          block_dy[b] = dy;
          const int w = std::min(kBlockWidth, width - dx);
          const int h = std::min(kBlockHeight, height - dy);
          const std::uint32_t row = (1u << w) - 1u;
          block_pixels[b] = static_cast<std::uint8_t>(h == 2 ? row | (row << kBlockWidth) : row);
          block_hits[b] = 0;
          block_on_character[b] = 0;
        }
      }
    }
  }
  region_begin.push_back(static_cast<std::uint32_t>(b));
}

}  // namespace sinew::rt
