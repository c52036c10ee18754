#include "raytrace/render/stages/tile_stages.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/sampling/sample_pattern.h"
#include "raytrace/render/stages/stage_support.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/traverse/traversal_shared.h"

namespace sinew::rt {

using namespace stages;

namespace {

// One light's terms for placing shadow rays, eight lanes at a time.
struct ShadowLight {
  bool point;
  Vec3x8 at, direction;
  float magnitude;
  std::uint8_t dark;  // clears the light's bit of s.lit

  ShadowLight(bool is_point, const Vec3& position, const Vec3& dir, int l)
      : point(is_point), at{Float8(position.x), Float8(position.y), Float8(position.z)},
        direction{Float8(dir.x), Float8(dir.y), Float8(dir.z)}, magnitude(detail::max_abs(position)),
        dark(static_cast<std::uint8_t>(~(1u << l))) {}

  Vec3x8 to_light(const Vec3x8& position) const { return point ? at - position : direction; }

  // The hits of block b whose surface faces the light; the others lose the
  // light's bit of s.lit (no ray needed).
  std::uint32_t facing(TileScratch& s, std::size_t b) const {
    const std::uint32_t lanes = s.block_hits[b];
    if (lanes == 0) return 0;
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 to = to_light(load3(s.px, s.py, s.pz, k0));
    const std::uint32_t toward = (dot(load3(s.gx, s.gy, s.gz, k0), to) > Float8(0.0f)).bits() & lanes;
    for (std::uint32_t away = lanes & ~toward; away != 0; away &= away - 1) {
      s.lit[k0 + static_cast<std::size_t>(std::countr_zero(away))] &= dark;
    }
    return toward;
  }

  // offset_origin's push of block b's hits along the camera-facing normal,
  // by the rounding bound (for a point light shadow_ray_from_light's wider
  // one): the offset, and the moved points.
  Vec3x8 offset(const TileScratch& s, std::size_t k0) const {
    return point ? surface_push_from(s, k0, at, Float8(magnitude)) : surface_push(s, k0);
  }

  // Block b's rays: the moved points one float further on every axis they
  // moved; a point light's run from the light to them.
  void place(TileScratch& s, std::size_t b) const {
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 push = offset(s, k0);
    place_moved(s, k0, load3(s.px, s.py, s.pz, k0) + push, push);
  }
  void place_moved(TileScratch& s, std::size_t k0, const Vec3x8& moved, const Vec3x8& push) const {
    const Vec3x8 end{step_away(moved.x, push.x), step_away(moved.y, push.y), step_away(moved.z, push.z)};
    store3(point ? end - at : end, s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
  }
};

void start_shadow_rays(const Light& light, TileScratch& s) {
  s.shadow_placed = 0;
  s.shadows_compacted = false;
  s.shadow_count = 0;
  s.shadow_region_begin.clear();
  s.shadows_from_point = light.kind == Light::Kind::kPoint;
  s.shadows_per_lane = false;
  s.shadow_origin = light.position;
  s.shadow_direction = light.direction;
  s.shadow_ends = Aabb::empty();  // only aiming bounds the ends
}

// Fine geometry's shadow packets: 8x8 pixels. Measured against 4x4 and
// 8x4 (and the whole 16x16 region) at 213,888 and 855,552 triangles
// (docs/RAYTRACE.md, "Shadow packets on fine meshes").
constexpr std::size_t kSplitBlocksX = 2;
constexpr std::size_t kSplitBlocksY = 4;
// Triangles this many pixels across or smaller count as fine: at least two
// in three neighbouring character pixels lie on different triangles.
constexpr double kFineTrianglePixels = 1.5;

// Whether the region's character hits lie on triangles about
// kFineTrianglePixels across or smaller: the share of neighbouring
// character pixels (within a block, across and down) on different
// triangles.
bool fine_geometry(const TileScratch& s, std::size_t b0, std::size_t b1) {
  // Per block, bit i of `across` for the pair (i, i + 1) of a row (bits 0-2
  // the top row, 4-6 the bottom one), bit i of `down` for (i, i + 4); a
  // pair counts when both its pixels are on a character. Without branches,
  // since it runs for every region, also where none splits.
  int pairs = 0, changes = 0;
  for (std::size_t b = b0; b < b1; ++b) {
    const unsigned on = s.block_on_character[b];
    if (on == 0) continue;
    const std::uint32_t* tri = s.triangle.data() + b * kBlockLanes;
    const std::uint32_t* inst = s.instance.data() + b * kBlockLanes;
    const auto same = [&](int i, int j) {
      return static_cast<unsigned>(tri[i] == tri[j]) & static_cast<unsigned>(inst[i] == inst[j]);
    };
    const unsigned same_across = same(0, 1) | same(1, 2) << 1 | same(2, 3) << 2 | same(4, 5) << 4 |
                                 same(5, 6) << 5 | same(6, 7) << 6;
    const unsigned same_down = same(0, 4) | same(1, 5) << 1 | same(2, 6) << 2 | same(3, 7) << 3;
    const unsigned across = on & (on >> 1) & 0x77u;
    const unsigned down = on & (on >> 4) & 0x0Fu;
    pairs += std::popcount(across) + std::popcount(down);
    changes += std::popcount(across & ~same_across) + std::popcount(down & ~same_down);
  }
  return pairs > 0 && static_cast<double>(changes) * kFineTrianglePixels >= static_cast<double>(pairs);
}

}  // namespace

TileCone shadow_tile_cone(const TileScratch& s) {
  if (!s.shadows_from_point || !(s.shadow_ends.lower.x <= s.shadow_ends.upper.x)) return {};
  Vec3 corners[8];
  for (int corner = 0; corner < 8; ++corner) {
    for (int a = 0; a < 3; ++a) {
      const float end = (corner >> a & 1) ? s.shadow_ends.upper[a] : s.shadow_ends.lower[a];
      corners[corner][a] = end - s.shadow_origin[a];
    }
  }
  return TileCone(s.shadow_origin, corners, 8);
}

void aim_shadow_rays(const Light& light, int l, TileScratch& s) {
  start_shadow_rays(light, s);
  s.shadows_aimed_only = true;
  const ShadowLight to(s.shadows_from_point, light.position, light.direction, l);
  Vec3x8 lo{Float8(kInf), Float8(kInf), Float8(kInf)}, hi{Float8(-kInf), Float8(-kInf), Float8(-kInf)};
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t toward = to.facing(s, b);
    s.shadow_lanes[b] = static_cast<std::uint8_t>(toward);
    if (toward == 0) continue;
    // The moved points of place(), bit for bit (the last step, one float
    // on, is left to the bound's growth), kept with their push for
    // offset_shadow_rays.
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 push = to.offset(s, k0);
    const Vec3x8 moved = load3(s.px, s.py, s.pz, k0) + push;
    store3(moved, s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
    store3(push, s.shadow_push_x, s.shadow_push_y, s.shadow_push_z, k0);
    const Mask8 m = Mask8::from_bits(toward);
    lo = select(m, Vec3x8{min(lo.x, moved.x), min(lo.y, moved.y), min(lo.z, moved.z)}, lo);
    hi = select(m, Vec3x8{max(hi.x, moved.x), max(hi.y, moved.y), max(hi.z, moved.z)}, hi);
    s.shadow_placed += static_cast<std::size_t>(std::popcount(toward));
  }
  if (s.shadow_placed == 0) return;
  // A ray ends one float on from its moved point (at most 2^-22 of the
  // coordinate, or a denormal step from zero): growing the box by 2^-21 of
  // the coordinates and the smallest normal float holds every end and its
  // rounding, and keeps the box on the light's side of a receiver the
  // offset cleared by far more.
  const Vec3 low(reduce_min(lo.x), reduce_min(lo.y), reduce_min(lo.z));
  const Vec3 high(reduce_max(hi.x), reduce_max(hi.y), reduce_max(hi.z));
  const float magnitude = std::max(detail::max_abs(low), detail::max_abs(high));
  const float grow = 0x1.0p-21f * magnitude + std::numeric_limits<float>::min();
  s.shadow_ends = {low - Vec3(grow), high + Vec3(grow)};
}

void offset_shadow_rays(TileScratch& s) {
  if (!s.shadows_aimed_only) return;
  s.shadows_aimed_only = false;
  const ShadowLight to(s.shadows_from_point, s.shadow_origin, s.shadow_direction, 0);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    if (s.shadow_lanes[b] == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    to.place_moved(s, k0, load3(s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0),
                   load3(s.shadow_push_x, s.shadow_push_y, s.shadow_push_z, k0));
  }
}

void place_shadow_rays(const Light& light, int l, TileScratch& s) {
  // In one pass, without the bound aiming makes: for tracers that take
  // every ray (the Embree peer of the benchmarks).
  start_shadow_rays(light, s);
  s.shadows_aimed_only = false;
  const ShadowLight to(s.shadows_from_point, light.position, light.direction, l);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t toward = to.facing(s, b);
    s.shadow_lanes[b] = static_cast<std::uint8_t>(toward);
    if (toward == 0) continue;
    to.place(s, b);
    s.shadow_placed += static_cast<std::size_t>(std::popcount(toward));
  }
}

namespace {

// The most runs of one origin per sample class and tile (compact_by_class);
// a tile whose hits turn a sphere light's disk more ways than that (a light
// among them) puts the rest of a class's rays in one run.
constexpr int kOriginRuns = 8;

// Segment rays (an area light's samples, ambient occlusion rays) in runs of
// one sample class each (render/sampling/sample_pattern.h), those from
// characters apart from those from static meshes, at most one packet long:
// a class's hits took the same sample this round, so their rays leave one
// point of a light where they share its disk (runs split by origin: the
// packet culls them with frusta from it, traverse/large_packet.cpp) or, for
// ambient occlusion and the sun, run nearly parallel where the surface is
// flat. Within a run the rays keep the tile's block order.
void compact_by_class(TileScratch& s) {
  constexpr std::size_t kRunRays = static_cast<std::size_t>(kMaxPacketGroups) * kBlockLanes;
  // Every block starts a whole number of interleaving blocks from the
  // tile's corner, so the tile's first pixels give each class's lanes of
  // every block.
  constexpr int kBlockRows = kBlockLanes / kBlockWidth;
  static_assert(kBlockWidth % kInterleave == 0 && kBlockRows % kInterleave == 0);
  std::array<std::uint32_t, kSampleClasses> class_lanes{};
  for (int y = 0; y < kInterleave; ++y) {
    for (int x = 0; x < kInterleave; ++x) {
      std::uint32_t repeats = 0;
      for (int ry = y; ry < kBlockRows; ry += kInterleave) {
        for (int rx = x; rx < kBlockWidth; rx += kInterleave) repeats |= 1u << (ry * kBlockWidth + rx);
      }
      class_lanes[static_cast<std::size_t>(sample_class(s.tile.x0 + x, s.tile.y0 + y))] |= repeats;
    }
  }
  // Runs class by class, those from characters first; within a run the
  // tile's block order. Written run after run, in address order: a
  // compress_store writes a whole group past its lanes.
  const Float8 t_max(s.shadow_tmax);
  s.shadow_count = 0;
  s.shadow_region_begin.assign(1, 0u);
  std::vector<std::uint8_t>& pending = s.segments_pending;
  // Raw pointers: a store through a float* may alias a vector's own, which
  // would reload every array's address after each store.
  const float* const from[3] = {s.shadow_from_x.data(), s.shadow_from_y.data(), s.shadow_from_z.data()};
  const float* const along[3] = {s.shadow_lane_x.data(), s.shadow_lane_y.data(), s.shadow_lane_z.data()};
  float* const origins[3] = {s.so_x.data(), s.so_y.data(), s.so_z.data()};
  float* const directions[3] = {s.sd_x.data(), s.sd_y.data(), s.sd_z.data()};
  float* const ends = s.s_tmax.data();
  std::uint32_t* const pixels = s.shadow_pixel.data();
  const std::uint8_t* const on_characters = s.block_on_character.data();
  for (const std::uint32_t of_class : class_lanes) {
    std::size_t first = s.blocks();
    for (std::size_t b = 0; b < s.blocks(); ++b) {
      pending[b] = static_cast<std::uint8_t>(s.shadow_lanes[b] & of_class);
      if (pending[b] != 0 && first == s.blocks()) first = b;
    }
    // Segments from a light's points: a run per origin (the class's first
    // pending ray's, then the next one's), so that each packet starts at
    // one point and takes the common-origin path; past kOriginRuns
    // origins the rest share a run. Other segments: one run per class.
    for (int origin_run = 0; first < s.blocks(); ++origin_run) {
      const bool by_origin = s.segments_share_origins && origin_run < kOriginRuns;
      const std::size_t k = first * kBlockLanes + static_cast<std::size_t>(std::countr_zero(pending[first]));
      const Vec3x8 origin{Float8(from[0][k]), Float8(from[1][k]), Float8(from[2][k])};
      const auto at_origin = [&](std::size_t b) -> std::uint32_t {
        if (!by_origin) return 0xFFu;
        const std::size_t k0 = b * kBlockLanes;
        return ((Float8::load(from[0] + k0) == origin.x) & (Float8::load(from[1] + k0) == origin.y) &
                (Float8::load(from[2] + k0) == origin.z))
            .bits();
      };
      for (const bool from_characters : {true, false}) {
        std::size_t run = 0;
        for (std::size_t b = first; b < s.blocks(); ++b) {
          if (pending[b] == 0) continue;
          const std::uint32_t on_character = on_characters[b];
          const std::uint32_t lanes =
              pending[b] & at_origin(b) & (from_characters ? on_character : ~on_character);
          if (lanes == 0) continue;
          pending[b] = static_cast<std::uint8_t>(pending[b] & ~lanes);
          const std::size_t count = static_cast<std::size_t>(std::popcount(lanes));
          if (run + count > kRunRays) {
            s.shadow_region_begin.push_back(static_cast<std::uint32_t>(s.shadow_count));
            run = 0;
          }
          const std::size_t k0 = b * kBlockLanes, i = s.shadow_count;
          for (int a = 0; a < 3; ++a) {
            compress_store(origins[a] + i, Float8::load(from[a] + k0), lanes);
            compress_store(directions[a] + i, Float8::load(along[a] + k0), lanes);
          }
          t_max.store(ends + i);
          compress_store_lane_indices(pixels + i, static_cast<std::uint32_t>(k0), lanes);
          s.shadow_count += count;
          run += count;
        }
        if (s.shadow_region_begin.back() != s.shadow_count) {
          s.shadow_region_begin.push_back(static_cast<std::uint32_t>(s.shadow_count));
        }
      }
      while (first < s.blocks() && pending[first] == 0) ++first;
    }
  }
  if (s.shadow_count == 0) s.shadow_region_begin.clear();
}

}  // namespace

void compact_shadow_rays(TileScratch& s) {
  if (s.shadows_compacted) return;
  s.shadows_compacted = true;
  if (s.shadows_per_lane) {
    compact_by_class(s);
    return;
  }
  const bool point = s.shadows_from_point;
  const float tmax = point ? 1.0f : kInf;
  const Vec3x8 light_at{Float8(s.shadow_origin.x), Float8(s.shadow_origin.y), Float8(s.shadow_origin.z)};
  const Vec3x8 light_dir{Float8(s.shadow_direction.x), Float8(s.shadow_direction.y), Float8(s.shadow_direction.z)};
  s.shadow_count = 0;
  s.shadow_region_begin.clear();
  // The rays of block b's lanes of `lanes`, compacted eight lanes at a time
  // (the arrays have a spare group).
  const auto add_block = [&](std::size_t b, std::uint32_t lanes) {
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 placed = load3(s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
    const Vec3x8 origin = point ? light_at : placed;
    const Vec3x8 direction = point ? placed : light_dir;
    const std::size_t i = s.shadow_count;
    compress_store(&s.so_x[i], origin.x, lanes);
    compress_store(&s.so_y[i], origin.y, lanes);
    compress_store(&s.so_z[i], origin.z, lanes);
    compress_store(&s.sd_x[i], direction.x, lanes);
    compress_store(&s.sd_y[i], direction.y, lanes);
    compress_store(&s.sd_z[i], direction.z, lanes);
    Float8(tmax).store(&s.s_tmax[i]);
    compress_store_lane_indices(&s.shadow_pixel[i], static_cast<std::uint32_t>(k0), lanes);
    s.shadow_count += static_cast<std::size_t>(std::popcount(lanes));
  };
  // Per region, the rays from characters and those from static meshes make
  // two runs (two packets): a silhouette region's rays end at two depths,
  // and one packet over both would reach every object between them.
  const auto close_run = [&] {
    if (s.shadow_region_begin.empty() || s.shadow_region_begin.back() != s.shadow_count) {
      s.shadow_region_begin.push_back(static_cast<std::uint32_t>(s.shadow_count));
    }
  };
  // The rays of the region's blocks [b0, b1) (`columns` to a row) whose
  // lanes `lanes_of(b)` gives, in packets of square x square_rows blocks.
  const auto add_squares = [&](std::size_t b0, std::size_t b1, std::size_t columns, std::size_t square,
                               std::size_t square_rows, auto&& lanes_of) {
    const std::size_t rows = columns == 0 ? 0 : (b1 - b0 + columns - 1) / columns;
    for (std::size_t sy = 0; sy < rows; sy += square_rows) {
      for (std::size_t sx = 0; sx < columns; sx += square) {
        for (std::size_t y = sy; y < std::min(rows, sy + square_rows); ++y) {
          for (std::size_t x = sx; x < std::min(columns, sx + square); ++x) {
            const std::size_t b = b0 + y * columns + x;
            if (b >= b1) continue;
            const std::uint32_t lanes = lanes_of(b);
            if (lanes != 0) add_block(b, lanes);
          }
        }
        close_run();
      }
    }
  };
  s.shadow_region_begin.push_back(0);
  for (std::size_t r = 0; r < s.regions(); ++r) {
    const std::size_t b0 = s.region_begin[r], b1 = s.region_begin[r + 1];
    std::uint32_t statics = 0;
    for (std::size_t b = b0; b < b1; ++b) statics |= s.shadow_lanes[b] & ~s.block_on_character[b];
    // The character rays in packets of the whole region, or on pixel-sized
    // triangles of 8x8-pixel squares. A large packet's rays all end on the
    // surface, so its leaves near the surface are reached by every group,
    // and there a finer mesh means more triangles per group: at 855,552
    // triangles 8x8-pixel packets take 25 triangle tests a shadow ray where
    // 16x16 take 37.
    const std::size_t columns = s.region_columns(r);
    const bool splittable = s.plan.split_fine_shadows && columns > kSplitBlocksX;
    const std::size_t rows = columns == 0 ? 0 : (b1 - b0 + columns - 1) / columns;
    const bool split = splittable && fine_geometry(s, b0, b1);
    add_squares(b0, b1, columns, split ? kSplitBlocksX : columns, split ? kSplitBlocksY : rows,
                [&](std::size_t b) { return s.block_on_character[b] & s.shadow_lanes[b]; });
    if (statics == 0) continue;
    // The static meshes' rays (a ground's) pass the characters away from
    // their ends: 8x8-pixel squares pay where the characters' triangles are
    // about a pixel (TracePlan::split_static_shadows), and cost more
    // where they are larger (docs/RAYTRACE.md, "Shadow packets on fine
    // meshes").
    const bool split_statics = splittable && s.plan.split_static_shadows;
    add_squares(b0, b1, columns, split_statics ? kSplitBlocksX : columns, split_statics ? kSplitBlocksY : rows,
                [&](std::size_t b) { return s.shadow_lanes[b] & ~s.block_on_character[b]; });
  }
  // No ray at all: no run.
  if (s.shadow_count == 0) s.shadow_region_begin.clear();
}

void make_shadow_rays(const Light& light, int l, TileScratch& s) {
  place_shadow_rays(light, l, s);
  compact_shadow_rays(s);
}

}  // namespace sinew::rt
