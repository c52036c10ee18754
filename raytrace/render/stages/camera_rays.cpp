#include "raytrace/render/stages/tile_stages.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/stages/stage_support.h"

namespace sinew::rt {

using namespace stages;

TileCone camera_tile_cone(const PinholeCamera& camera, const Tile& tile) {
  const float x0 = static_cast<float>(tile.x0) + 0.5f, x1 = static_cast<float>(tile.x1) - 0.5f;
  const float y0 = static_cast<float>(tile.y0) + 0.5f, y1 = static_cast<float>(tile.y1) - 0.5f;
  alignas(32) const float xs[8] = {x0, x1, x0, x1, x0, x1, x0, x1};
  alignas(32) const float ys[8] = {y0, y0, y1, y1, y0, y0, y1, y1};
  alignas(32) float q[3][8];
  const Vec3x8 d = camera.directions_at(Float8::load(xs), Float8::load(ys));
  d.x.store(q[0]);
  d.y.store(q[1]);
  d.z.store(q[2]);
  Vec3 corners[4];
  for (int i = 0; i < 4; ++i) corners[i] = Vec3(q[0][i], q[1][i], q[2][i]);
  return TileCone(camera.eye(), corners, 4);
}

void generate_camera_rays(const PinholeCamera& camera, TileScratch& s) {
  // Each column's and each row's offset once per tile (pixel centres,
  // integer + 0.5, exact in float, as PinholeCamera::ray), out to the
  // blocks' edges.
  thread_local std::vector<float> columns, rows;
  columns.resize(static_cast<std::size_t>(s.blocks_x) * kBlockWidth);
  rows.resize(static_cast<std::size_t>(s.blocks_y) * kBlockHeight);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    columns[i] = camera.right_offset(static_cast<float>(s.tile.x0 + static_cast<int>(i)) + 0.5f);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i] = camera.up_offset(static_cast<float>(s.tile.y0 + static_cast<int>(i)) + 0.5f);
  }
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    // Lane i sits at (i % 4, i / 4) in its block.
    const float* const a = &columns[static_cast<std::size_t>(s.block_dx[b])];
    const float* const r = &rows[static_cast<std::size_t>(s.block_dy[b])];
    static_assert(kBlockWidth == 4 && kBlockHeight == 2, "a block's lanes: four columns, two rows");
    const Float8 right = repeat4(a);
    const Float8 up = halves(r[0], r[1]);
    store3(camera.directions_from(right, up), s.dir_x, s.dir_y, s.dir_z, b * kBlockLanes);
  }
}

}  // namespace sinew::rt
