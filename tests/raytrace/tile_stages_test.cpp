// The tile stages (render/stages/tile_stages.h): the SoA stages reproduce
// the scalar camera and surface code bit for bit (camera directions,
// surfaces and shadow origins, blocks whose lanes hit several triangles),
// aimed shadow rays end inside their bound, and compacted shadow rays run
// region by region, as 8x8-pixel packets where the triangles are
// pixel-sized.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "tests/raytrace/render_test_support.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::kInf;
using testing_support::scene;
using testing_support::unit;

TEST(TileStages, CameraDirectionsAreTheCameraRays) {
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 47.0f}, 37, 23)
          .value();
  // Blocks one by one, and in regions of large packets (block order is
  // then region by region).
  for (const auto& [region_x, region_y] : {std::pair{1, 1}, std::pair{4, 8}, std::pair{8, 8}}) {
    rt::TileScratch s;
    rt::TracePlan plan;
    plan.region_blocks_x = region_x;
    plan.region_blocks_y = region_y;
    s.prepare(Tile{5, 3, 18, 14, 0}, plan);  // 13x11: partial blocks at both edges
    rt::generate_camera_rays(camera, s);
    std::size_t pixels = 0;
    for (std::size_t k = 0; k < s.lanes; ++k) {
      if (!s.is_pixel(k)) continue;
      ++pixels;
      const Ray ray = camera.ray(s.pixel_x(k), s.pixel_y(k));
      ASSERT_EQ(std::bit_cast<std::uint32_t>(s.dir_x[k]), std::bit_cast<std::uint32_t>(ray.direction.x)) << k;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(s.dir_y[k]), std::bit_cast<std::uint32_t>(ray.direction.y)) << k;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(s.dir_z[k]), std::bit_cast<std::uint32_t>(ray.direction.z)) << k;
    }
    EXPECT_EQ(pixels, 13u * 11u);
  }
}

TEST(TileStages, SurfacesAndShadowOriginsAreTheScalarOnes) {
  const rt::Scene& sc = scene();
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f}, 64, 64)
          .value();
  rt::Light light;
  light.position = Vec3(2.0f, 4.0f, 3.0f);
  std::size_t hits = 0, rays = 0, split_regions = 0, square_runs = 0;
  // Regions of one block (8-ray packets) and of 4x8 blocks (256 rays).
  for (const int region_x : {1, 4}) {
    for (int ty = 0; ty < 64; ty += 16) {
      for (int tx = 0; tx < 64; tx += 16) {
        rt::TileScratch s;
        rt::TracePlan plan;  // 8-ray packets over either layout
        plan.region_blocks_x = region_x;
        plan.region_blocks_y = 2 * region_x;
        s.prepare(Tile{tx, ty, tx + 16, ty + 16, 0}, plan);
        rt::generate_camera_rays(camera, s);
        rt::TraversalCounters counters;
        rt::trace_primary(sc, camera, TriangleTest::kFast, s, counters);
        std::fill(s.lit.begin(), s.lit.end(), std::uint8_t{1});
        rt::reconstruct_surfaces(sc, {Vec3(0.7f), camera.pixel_spread()}, s);
        rt::make_shadow_rays(light, 0, s);
        const auto on_character = [&](std::size_t k) {
          return sc.object_slots()[s.instance[k]].kind == rt::Scene::ObjectKind::kCharacter;
        };
        const auto region_of = [&](std::size_t k) {
          const std::size_t b = k / rt::kBlockLanes;
          return static_cast<std::size_t>(std::upper_bound(s.region_begin.begin(), s.region_begin.end(), b) -
                                          s.region_begin.begin());
        };
        // Which ray each lane got.
        std::vector<std::size_t> ray_of(s.lanes, s.lanes);
        for (std::size_t i = 0; i < s.shadow_count; ++i) {
          ASSERT_EQ(ray_of[s.shadow_pixel[i]], s.lanes) << "one ray per lane";
          ray_of[s.shadow_pixel[i]] = i;
        }
        std::size_t lane_rays = 0;
        for (std::size_t k = 0; k < s.lanes; ++k) {
          if (!s.hit(k)) continue;
          ++hits;
          const Hit hit{s.t[k], s.u[k], s.v[k], s.triangle[k], s.instance[k]};
          const rt::SurfacePoint p = rt::surface_at(sc, hit, Vec3(0.7f));
          const Vec3 dir(s.dir_x[k], s.dir_y[k], s.dir_z[k]);
          Vec3 facing = p.geometric_normal;
          if (glm::dot(facing, dir) > 0.0f) facing = -facing;
          Vec3 n = p.shading_normal;
          if (glm::dot(n, facing) < 0.0f) n = -n;
          ASSERT_EQ(Vec3(s.px[k], s.py[k], s.pz[k]), p.position) << k;
          ASSERT_EQ(Vec3(s.gx[k], s.gy[k], s.gz[k]), facing) << k;
          ASSERT_EQ(Vec3(s.nx[k], s.ny[k], s.nz[k]), n) << k;
          ASSERT_EQ(Vec3(s.ar[k], s.ag[k], s.ab[k]), p.albedo) << k;
          ASSERT_EQ(s.error[k], p.error.x) << k;
          const bool lane_on_character = (s.block_on_character[k / rt::kBlockLanes] >> (k % rt::kBlockLanes) & 1u) != 0;
          ASSERT_EQ(lane_on_character, on_character(k)) << k;
          if (glm::dot(facing, light.position - p.position) <= 0.0f) {
            ASSERT_EQ(s.lit[k], 0u) << "facing away from the light: dark without a ray";
            ASSERT_EQ(ray_of[k], s.lanes) << "no ray facing away from the light";
            continue;
          }
          const std::size_t i = ray_of[k];
          ASSERT_LT(i, s.shadow_count) << k;
          const Ray ray = rt::shadow_ray_from_light(p, facing, light.position);
          ASSERT_EQ(s.shadow_ray(i).origin, light.position) << k;
          ASSERT_EQ(s.shadow_ray(i).direction, ray.direction) << k;
          ASSERT_EQ(s.shadow_ray(i).t_max, 1.0f) << k;
          ++lane_rays;
          ++rays;
        }
        EXPECT_EQ(lane_rays, s.shadow_count);
        // Runs: region by region, a region's rays on characters, then its
        // rays on static meshes, each in lane order; a region on pixel-sized
        // triangles (the mannequins at 64x64) gives its character rays one
        // run per 8x8 pixels.
        if (s.shadow_count == 0) {
          EXPECT_TRUE(s.shadow_region_begin.empty());
          continue;
        }
        ASSERT_GE(s.shadow_region_begin.size(), 2u);
        EXPECT_EQ(s.shadow_region_begin.front(), 0u);
        EXPECT_EQ(s.shadow_region_begin.back(), s.shadow_count);
        std::size_t last_region = 0, last_kind = 0;
        for (std::size_t r = 0; r + 1 < s.shadow_region_begin.size(); ++r) {
          const std::size_t i0 = s.shadow_region_begin[r], i1 = s.shadow_region_begin[r + 1];
          ASSERT_LT(i0, i1) << "no empty run";
          const std::size_t region = region_of(s.shadow_pixel[i0]);
          const std::size_t kind = on_character(s.shadow_pixel[i0]) ? 0 : 1;
          for (std::size_t i = i0; i < i1; ++i) {
            ASSERT_EQ(region_of(s.shadow_pixel[i]), region) << i;
            ASSERT_EQ(on_character(s.shadow_pixel[i]) ? 0u : 1u, kind) << i;
            if (i > i0) {
              ASSERT_LT(s.shadow_pixel[i - 1], s.shadow_pixel[i]);
            }
          }
          if (r > 0) {
            const bool next_square = region == last_region && kind == 0 && last_kind == 0;
            ASSERT_TRUE(region > last_region || (region == last_region && kind > last_kind) || next_square) << r;
            if (region == last_region && kind > last_kind) ++split_regions;
            if (next_square) ++square_runs;
          }
          if (kind == 0) {
            // Within one 8x8 square when the region's character rays split,
            // and in any case within one region.
            const auto square = [&](std::size_t k) { return std::pair(s.pixel_x(k) / 8, s.pixel_y(k) / 8); };
            const bool split = (r > 0 && region == last_region && last_kind == 0) ||
                               (r + 2 < s.shadow_region_begin.size() &&
                                region_of(s.shadow_pixel[i1]) == region && on_character(s.shadow_pixel[i1]));
            for (std::size_t i = i0; split && i < i1; ++i) {
              ASSERT_EQ(square(s.shadow_pixel[i]), square(s.shadow_pixel[i0])) << i;
            }
          }
          last_region = region;
          last_kind = kind;
        }
      }
    }
  }
  EXPECT_GT(hits, 2000u);
  EXPECT_GT(rays, 1000u);
  EXPECT_GT(split_regions, 4u) << "regions with rays on both kinds of mesh";
  EXPECT_GT(square_runs, 0u) << "regions whose character rays run as 8x8-pixel packets";
}

// Blocks whose lanes hit several triangles: the same triangle index on
// both characters and on the ground, lanes that miss between them, in every
// order. Each block's corners are loaded once per distinct (instance,
// triangle) and blended into its lanes (render/stages/surfaces.cpp
// gather_lanes); every lane must still be surface_at's, bit for bit.
TEST(TileStages, SurfacesOfBlocksOnSeveralTrianglesAreTheScalarOnes) {
  const rt::Scene& sc = scene();
  std::vector<std::uint32_t> characters, statics;
  for (std::uint32_t id = 0; id < sc.object_slots().size(); ++id) {
    (sc.object_slots()[id].kind == rt::Scene::ObjectKind::kCharacter ? characters : statics).push_back(id);
  }
  ASSERT_GE(characters.size(), 2u);
  ASSERT_GE(statics.size(), 1u);
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f}, 64, 64)
          .value();
  // (instance, triangle) choices: triangle 1 on each object, triangle 2 on
  // the first character; lanes draw from the first `kinds` of them.
  const std::array<std::pair<std::uint32_t, std::uint32_t>, 4> choices = {
      {{characters[0], 1u}, {characters[1], 1u}, {statics[0], 1u}, {characters[0], 2u}}};
  std::mt19937 g(11);
  std::size_t checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    rt::TileScratch s;
    s.prepare(Tile{0, 0, 16, 8, 0});
    rt::generate_camera_rays(camera, s);
    const std::size_t kinds = 1 + static_cast<std::size_t>(trial % 4);
    for (std::size_t b = 0; b < s.blocks(); ++b) {
      std::uint32_t hits = 0;
      for (int lane = 0; lane < rt::kBlockLanes; ++lane) {
        const std::size_t k = b * rt::kBlockLanes + static_cast<std::size_t>(lane);
        const bool miss = trial % 3 == 0 && g() % 4 == 0;
        const auto [instance, triangle] = choices[g() % kinds];
        s.t[k] = miss ? kInf : 1.0f + unit(g);
        s.u[k] = 0.5f * unit(g);
        s.v[k] = 0.5f * unit(g);
        s.triangle[k] = miss ? kInvalidId : triangle;
        s.instance[k] = miss ? kInvalidId : instance;
        hits |= miss ? 0u : 1u << lane;
      }
      s.block_hits[b] = static_cast<std::uint8_t>(hits);
    }
    rt::reconstruct_surfaces(sc, {Vec3(0.7f), camera.pixel_spread()}, s);
    for (std::size_t k = 0; k < s.lanes; ++k) {
      if (!s.hit(k)) continue;
      const rt::SurfacePoint p = rt::surface_at(sc, Hit{s.t[k], s.u[k], s.v[k], s.triangle[k], s.instance[k]}, Vec3(0.7f));
      const Vec3 dir(s.dir_x[k], s.dir_y[k], s.dir_z[k]);
      Vec3 facing = p.geometric_normal;
      if (glm::dot(facing, dir) > 0.0f) facing = -facing;
      Vec3 n = p.shading_normal;
      if (glm::dot(n, facing) < 0.0f) n = -n;
      ASSERT_EQ(Vec3(s.px[k], s.py[k], s.pz[k]), p.position) << "trial " << trial << " lane " << k;
      ASSERT_EQ(Vec3(s.gx[k], s.gy[k], s.gz[k]), facing) << "trial " << trial << " lane " << k;
      ASSERT_EQ(Vec3(s.nx[k], s.ny[k], s.nz[k]), n) << "trial " << trial << " lane " << k;
      ASSERT_EQ(Vec3(s.ar[k], s.ag[k], s.ab[k]), p.albedo) << "trial " << trial << " lane " << k;
      ASSERT_EQ(s.error[k], p.error.x) << "trial " << trial << " lane " << k;
      const bool lane_on_character = (s.block_on_character[k / rt::kBlockLanes] >> (k % rt::kBlockLanes) & 1u) != 0;
      ASSERT_EQ(lane_on_character, sc.object_slots()[s.instance[k]].kind == rt::Scene::ObjectKind::kCharacter);
      ++checked;
    }
  }
  EXPECT_GT(checked, 20000u);
}

// aim_shadow_rays bounds where the rays of offset_shadow_rays end without
// computing them: every end (a directional light's ray origin; for a point
// light the rounded direction from the light, which the bound's corner
// directions must hold) lies inside s.shadow_ends, at coordinates from
// 1e-3 to 1e6, with surfaces at zero too. The bound stays on the lit side
// of a flat receiver, so a ground in the open is culled.
TEST(TileStages, AimedShadowRaysEndInsideTheirBound) {
  std::mt19937 g(7);
  std::size_t checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const float scale = std::pow(10.0f, -3.0f + 9.0f * unit(g));
    rt::TileScratch s;
    s.prepare(Tile{0, 0, 8, 4, 0});
    const Vec3 centre = scale * Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f);
    for (std::size_t b = 0; b < s.blocks(); ++b) s.block_hits[b] = static_cast<std::uint8_t>(g());
    for (std::size_t k = 0; k < s.lanes; ++k) {
      const Vec3 p = trial % 10 == 0 ? Vec3(0.0f) : centre + 0.1f * scale * Vec3(unit(g), unit(g), unit(g));
      const Vec3 n = glm::normalize(Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) + Vec3(0.0f, 0.0f, 1e-3f));
      s.px[k] = p.x;
      s.py[k] = p.y;
      s.pz[k] = p.z;
      s.gx[k] = n.x;
      s.gy[k] = n.y;
      s.gz[k] = n.z;
      s.error[k] = 4.2e-7f * std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
      s.lit[k] = 1;
    }
    rt::Light light;
    light.kind = trial % 2 == 0 ? rt::Light::Kind::kPoint : rt::Light::Kind::kDirectional;
    light.position = centre + 3.0f * scale * Vec3(unit(g) - 0.5f, unit(g) - 0.5f, 1.0f);
    light.direction = glm::normalize(Vec3(unit(g) - 0.5f, unit(g) - 0.5f, 1.0f));
    rt::aim_shadow_rays(light, 0, s);
    ASSERT_TRUE(s.shadows_aimed_only);
    const std::vector<std::uint8_t> aimed(s.shadow_lanes.begin(), s.shadow_lanes.begin() + static_cast<long>(s.blocks()));
    const Aabb ends = s.shadow_ends;
    rt::offset_shadow_rays(s);
    ASSERT_FALSE(s.shadows_aimed_only);
    // The same lanes as place_shadow_rays picks.
    rt::TileScratch placed = s;
    rt::place_shadow_rays(light, 0, placed);
    for (std::size_t b = 0; b < s.blocks(); ++b) ASSERT_EQ(aimed[b], placed.shadow_lanes[b]) << b;
    for (std::size_t b = 0; b < s.blocks(); ++b) {
      for (std::uint32_t m = aimed[b]; m != 0; m &= m - 1) {
        const std::size_t k = b * rt::kBlockLanes + static_cast<std::size_t>(std::countr_zero(m));
        const Vec3 lane(s.shadow_lane_x[k], s.shadow_lane_y[k], s.shadow_lane_z[k]);
        ASSERT_EQ(lane, Vec3(placed.shadow_lane_x[k], placed.shadow_lane_y[k], placed.shadow_lane_z[k])) << k;
        for (int a = 0; a < 3; ++a) {
          if (light.kind == rt::Light::Kind::kDirectional) {
            ASSERT_GE(lane[a], ends.lower[a]) << trial << " " << k;
            ASSERT_LE(lane[a], ends.upper[a]) << trial << " " << k;
          } else {
            ASSERT_GE(lane[a], ends.lower[a] - light.position[a]) << trial << " " << k;
            ASSERT_LE(lane[a], ends.upper[a] - light.position[a]) << trial << " " << k;
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000u);

  // A flat receiver lit from above: the bound lies above it.
  rt::TileScratch s;
  s.prepare(Tile{0, 0, 8, 4, 0});
  for (std::size_t k = 0; k < s.lanes; ++k) {
    s.px[k] = 100.0f + static_cast<float>(k);
    s.py[k] = -50.0f;
    s.pz[k] = 0.0f;
    s.gx[k] = s.gy[k] = 0.0f;
    s.gz[k] = 1.0f;
    s.error[k] = 4.2e-7f * 132.0f;
  }
  std::fill(s.block_hits.begin(), s.block_hits.end(), std::uint8_t{0xFF});
  rt::Light light;
  light.position = Vec3(0.0f, 0.0f, 400.0f);
  rt::aim_shadow_rays(light, 0, s);
  EXPECT_EQ(s.shadow_placed, s.lanes);
  EXPECT_GT(s.shadow_ends.lower.z, 0.0f) << "the ends are off the receiver, and so is their bound";
}

// A 16x16-pixel region of 4x8 blocks, every pixel with a shadow ray to a
// point light, compacted: pixel k on a character where on_character(k)
// (else on the ground), on triangle triangle_of(k).
template <class OnCharacter, class TriangleOf>
rt::TileScratch compacted_region(bool split, bool split_statics, OnCharacter&& on_character,
                                 TriangleOf&& triangle_of) {
  rt::TileScratch s;
  rt::TracePlan plan = rt::plan_for_packet_rays(256);
  plan.split_fine_shadows = split;
  plan.split_static_shadows = split_statics;
  s.prepare(Tile{0, 0, 16, 16, 0}, plan);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    s.block_hits[b] = 0xFF;
    s.block_on_character[b] = on_character(b * 8) ? 0xFF : 0x00;
    s.shadow_lanes[b] = 0xFF;
  }
  for (std::size_t k = 0; k < s.lanes; ++k) {
    s.triangle[k] = triangle_of(k);
    s.instance[k] = 0;
    s.shadow_lane_x[k] = static_cast<float>(k);
    s.shadow_lane_y[k] = 1.0f;
    s.shadow_lane_z[k] = -1.0f;
  }
  s.shadows_from_point = true;
  s.shadow_origin = Vec3(0.0f, 5.0f, 0.0f);
  s.shadows_aimed_only = false;
  s.shadows_compacted = false;
  rt::compact_shadow_rays(s);
  return s;
}

// Every pixel on a character, lane i of block b on triangle 10 * b + ids[i]
// (triangles of different blocks never meet in a pair).
rt::TileScratch fine_region(const std::array<std::uint32_t, 8>& ids, bool split) {
  return compacted_region(
      split, false, [](std::size_t) { return true; },
      [&](std::size_t k) { return static_cast<std::uint32_t>(10 * (k / 8)) + ids[k % 8]; });
}

// Four runs, run r holding the 64 rays of the 8x8 quadrant (r % 2, r / 2),
// every ray of the region once and its own.
void expect_quadrant_runs(const rt::TileScratch& s) {
  ASSERT_EQ(s.shadow_region_begin.size(), 5u);
  std::vector<int> seen(256, 0);
  for (std::size_t run = 0; run < 4; ++run) {
    for (std::size_t i = s.shadow_region_begin[run]; i < s.shadow_region_begin[run + 1]; ++i) {
      const std::size_t k = s.shadow_pixel[i];
      const int x = s.pixel_x(k), y = s.pixel_y(k);
      EXPECT_EQ(x / 8, static_cast<int>(run % 2)) << "ray " << i;
      EXPECT_EQ(y / 8, static_cast<int>(run / 2)) << "ray " << i;
      ++seen[static_cast<std::size_t>(16 * y + x)];
      EXPECT_EQ(s.sd_x[i], static_cast<float>(k));  // the lane's own ray
    }
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 256);
}

// Lanes 0-3 are a block's top row, 4-7 its bottom row: ten neighbouring
// pairs (six across, four down). A region splits when at least two in three
// of its pairs lie on different triangles (hand-counted below).
TEST(TileStages, ShadowRaysOfRegionsOnPixelSizedTrianglesRunAsEightByEightPackets) {
  const std::array<std::uint32_t, 8> distinct{0, 1, 2, 3, 4, 5, 6, 7};  // 10 of 10 pairs differ
  const std::array<std::uint32_t, 8> seven{0, 0, 1, 2, 3, 0, 1, 4};     // 2 + 3 across, 2 down: 7
  const std::array<std::uint32_t, 8> six{0, 0, 1, 2, 3, 0, 1, 2};       // 2 + 3 across, 1 down: 6
  const std::array<std::uint32_t, 8> one{5, 5, 5, 5, 5, 5, 5, 5};       // none
  const std::vector<std::uint32_t> quadrants{0, 64, 128, 192, 256};
  const std::vector<std::uint32_t> whole{0, 256};
  EXPECT_EQ(fine_region(distinct, true).shadow_region_begin, quadrants);
  EXPECT_EQ(fine_region(seven, true).shadow_region_begin, quadrants);
  EXPECT_EQ(fine_region(six, true).shadow_region_begin, whole);
  EXPECT_EQ(fine_region(one, true).shadow_region_begin, whole);
  EXPECT_EQ(fine_region(distinct, false).shadow_region_begin, whole);
  expect_quadrant_runs(fine_region(distinct, true));
}

// The top eight rows on a character's pixel-sized triangles (every pixel
// its own), the bottom eight on the ground: lanes 0-127 are blocks 0-15, the
// top four rows of 4x2-pixel blocks.
rt::TileScratch half_ground_region(bool split, bool split_statics) {
  return compacted_region(
      split, split_statics, [](std::size_t k) { return k < 128; },
      [](std::size_t k) { return static_cast<std::uint32_t>(k); });
}

// The character's rays run first, then the ground's; the ground's go in
// 8x8-pixel runs only where the frame's characters look fine
// (TracePlan::split_static_shadows) and splitting is on at all.
TEST(TileStages, StaticShadowRaysRunAsEightByEightPacketsWhereCharactersLookFine) {
  EXPECT_EQ(half_ground_region(true, true).shadow_region_begin, (std::vector<std::uint32_t>{0, 64, 128, 192, 256}));
  EXPECT_EQ(half_ground_region(true, false).shadow_region_begin, (std::vector<std::uint32_t>{0, 64, 128, 256}));
  EXPECT_EQ(half_ground_region(false, true).shadow_region_begin, (std::vector<std::uint32_t>{0, 128, 256}));
  EXPECT_EQ(half_ground_region(false, false).shadow_region_begin, (std::vector<std::uint32_t>{0, 128, 256}));
  // The character's two quadrants on top, then the ground's two below.
  expect_quadrant_runs(half_ground_region(true, true));
}

}  // namespace
}  // namespace sinew
