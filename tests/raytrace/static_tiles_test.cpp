// Static tiles (cull/static_tiles.h): tiles that reach only small
// static meshes gather their triangles and test them directly, and find
// each camera ray's hit and each shadow ray's occlusion as single rays and
// brute force do; a tile's cone never drops a triangle a ray inside it
// hits; a floor mesh's tile gathers its cells from the mesh's tree, and a
// tile that sees too much of the floor walks it with large packets.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/scene/scene.h"
#include "raytrace/cull/static_tiles.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/raytrace/render_test_support.h"
#include "tests/support/brute_force.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::kInf;
using testing_support::scene;
using testing_support::unit;

// Ground and wall quads and a mesh with a zero-area triangle: a scene of
// small static meshes only, whose tiles take the direct tests.
std::unique_ptr<rt::Scene> make_static_scene() {
  auto scene = std::make_unique<rt::Scene>();
  rt::StaticMeshDesc ground;
  ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  rt::StaticMeshDesc wall;  // tilted, crossing the ground
  wall.positions = {{-1, -0.5f, -1}, {1, -0.5f, -1.2f}, {-1, 2, -0.4f}, {1, 2, -0.6f}};
  wall.triangles = {{0, 1, 2}, {1, 3, 2}};
  rt::StaticMeshDesc sliver;  // a collinear triangle before a real one
  sliver.positions = {{-0.5f, 0.2f, 0.5f}, {0.0f, 0.7f, 0.5f}, {0.5f, 1.2f, 0.5f}, {0.6f, 0.1f, 0.4f}};
  sliver.triangles = {{0, 1, 2}, {0, 3, 2}};
  for (const rt::StaticMeshDesc* mesh : {&ground, &wall, &sliver}) EXPECT_TRUE(scene->add_static_mesh(*mesh).ok());
  JobSystem jobs(1);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return scene;
}

// A camera from `eye` toward `target` and one tile over its whole w x h
// image, its rays generated.
rt::PinholeCamera camera_tile(const Vec3& eye, const Vec3& target, float fov_degrees, int w, int h,
                              rt::TileScratch& s) {
  const auto camera = rt::PinholeCamera::create({eye, target, Vec3(0, 1, 0), fov_degrees}, w, h).value();
  s.prepare(Tile{0, 0, w, h, 0});
  rt::generate_camera_rays(camera, s);
  return camera;
}

// The tile bound of s's camera rays, as trace_primary builds it.
rt::RayBound camera_bound(const rt::PinholeCamera& camera, const rt::TileScratch& s) {
  rt::RayBound bound;
  for (std::size_t b = 0; b < s.lanes / 8; ++b) {
    const float* const d[3] = {&s.dir_x[b * 8], &s.dir_y[b * 8], &s.dir_z[b * 8]};
    bound.add_lanes(camera.eye(), d, 0.0f, kInf, s.block_pixels[b]);
  }
  return bound;
}

// The bound of s's shadow rays (padded to whole groups).
rt::RayBound shadow_bound(const rt::TileScratch& s) {
  rt::RayBound bound;
  static const float zeros[8] = {};
  for (std::size_t i = 0; i < s.shadow_count; i += 8) {
    const std::size_t n = std::min<std::size_t>(8, s.shadow_count - i);
    const float* const o[3] = {&s.so_x[i], &s.so_y[i], &s.so_z[i]};
    const float* const d[3] = {&s.sd_x[i], &s.sd_y[i], &s.sd_z[i]};
    bound.add_lanes(o, d, zeros, &s.s_tmax[i], (1u << n) - 1u);
  }
  return bound;
}

// Every camera lane of s equals the single ray's hit (bit for bit) and
// brute force's; returns the hit count per instance id.
std::vector<std::size_t> expect_single_ray_hits(const rt::Scene& sc, const rt::PinholeCamera& camera,
                                                const rt::TileScratch& s) {
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  std::vector<std::size_t> per_instance(8, 0);
  for (std::size_t k = 0; k < s.lanes; ++k) {
    Ray ray;
    ray.origin = camera.eye();
    ray.direction = Vec3(s.dir_x[k], s.dir_y[k], s.dir_z[k]);
    const Hit single = s.is_pixel(k) ? rt::intersect(sc, ray, TriangleTest::kFast) : Hit{};
    EXPECT_EQ(s.triangle[k], single.triangle_id) << k;
    EXPECT_EQ(s.instance[k], single.instance_id) << k;
    EXPECT_EQ(s.hit(k), single.valid()) << k;
    if (!single.valid()) {
      EXPECT_EQ(s.t[k], kInf) << k;
      continue;
    }
    ++per_instance[single.instance_id];
    EXPECT_EQ(std::bit_cast<std::uint32_t>(s.t[k]), std::bit_cast<std::uint32_t>(single.t)) << k;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(s.u[k]), std::bit_cast<std::uint32_t>(single.u)) << k;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(s.v[k]), std::bit_cast<std::uint32_t>(single.v)) << k;
    const Hit ref = testing_support::nearest(soup, ray, TriangleTest::kFast);
    EXPECT_TRUE(testing_support::same_nearest(single, ref, soup, ray, TriangleTest::kFast)) << k;
    if (::testing::Test::HasFailure()) break;
  }
  return per_instance;
}

// Every shadow ray of s: light 1's bit cleared exactly when the single ray
// (and brute force) is blocked, light 0's untouched; returns the blocked count.
std::size_t expect_single_ray_occlusion(const rt::Scene& sc, const rt::TileScratch& s) {
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  std::size_t blocked = 0;
  for (std::size_t i = 0; i < s.shadow_count; ++i) {
    Ray ray;
    ray.origin = Vec3(s.so_x[i], s.so_y[i], s.so_z[i]);
    ray.direction = Vec3(s.sd_x[i], s.sd_y[i], s.sd_z[i]);
    ray.t_max = s.s_tmax[i];
    const bool single = rt::occluded(sc, ray, TriangleTest::kFast);
    EXPECT_EQ(single, testing_support::any_hit(soup, ray, TriangleTest::kFast)) << i;
    EXPECT_EQ((s.lit[s.shadow_pixel[i]] & 0b10) == 0, single) << i;
    EXPECT_EQ(s.lit[s.shadow_pixel[i]] & 0b01, 1) << "other lights untouched";
    blocked += single ? 1 : 0;
  }
  return blocked;
}

// Tiles that reach only small static meshes: each camera ray's hit and each
// shadow ray's occlusion are the single ray's (and brute force's), with
// partial blocks at the image edge, invalid lanes and finite and infinite
// t ranges; the watertight test and bone objects keep the general path.
TEST(StaticTiles, SmallMeshesFindTheSingleRayHits) {
  const std::unique_ptr<rt::Scene> sc = make_static_scene();
  std::vector<std::uint32_t> objects(sc->top_level().objects().size());
  for (std::uint32_t i = 0; i < objects.size(); ++i) objects[i] = i;
  ASSERT_EQ(objects.size(), 3u);

  rt::TileScratch s;  // 13 x 11: partial blocks on the right and bottom
  const auto camera = camera_tile(Vec3(0.3f, 1.1f, 3.0f), Vec3(0.0f, 0.5f, 0.0f), 70.0f, 13, 11, s);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  s.dir_x[3] = nan;
  s.dir_x[9] = s.dir_y[9] = s.dir_z[9] = 0.0f;
  s.dir_z[17] = -kInf;
  rt::StaticTile tile;
  const rt::RayBound bound = camera_bound(camera, s);
  EXPECT_FALSE(rt::gather_static_tile(*sc, TriangleTest::kWatertight, bound, 0.0f, objects, tile));
  EXPECT_FALSE(rt::gather_static_tile(*sc, TriangleTest::kFast, bound, 0.0f, {}, tile));
  EXPECT_FALSE(rt::gather_static_tile(scene(), TriangleTest::kFast, bound, 0.0f, std::vector<std::uint32_t>{0}, tile))
      << "a bone of the mannequins";
  ASSERT_TRUE(rt::gather_static_tile(*sc, TriangleTest::kFast, bound, 0.0f, objects, tile));
  EXPECT_EQ(tile.triangles.size(), 6u) << "small meshes whole";
  EXPECT_EQ(tile.meshes, 3u);
  rt::TraversalCounters counters;
  rt::intersect_static_tile(tile, camera, s, counters);
  EXPECT_GT(counters.triangle_tests, 0u);
  const std::vector<std::size_t> per_mesh = expect_single_ray_hits(*sc, camera, s);
  for (std::uint32_t m = 0; m < 3; ++m) EXPECT_GT(per_mesh[m], 0u) << "every mesh is seen";

  // Shadow rays: scattered origins, mixed directions, to a point (t_max 1)
  // or unbounded; a count that leaves a partial last group.
  std::mt19937 g(5);
  s.shadow_count = 61;
  std::fill(s.lit.begin(), s.lit.end(), std::uint8_t{0b11});
  for (std::size_t i = 0; i < s.shadow_count; ++i) {
    s.shadow_pixel[i] = static_cast<std::uint32_t>(i);
    const Vec3 o(4.0f * unit(g) - 2.0f, 2.0f * unit(g) + 0.01f, 4.0f * unit(g) - 2.0f);
    const Vec3 d(4.0f * unit(g) - 2.0f, 3.0f * unit(g) - 2.0f, 4.0f * unit(g) - 2.0f);
    s.so_x[i] = o.x;
    s.so_y[i] = o.y;
    s.so_z[i] = o.z;
    s.sd_x[i] = i == 7 ? nan : d.x;
    s.sd_y[i] = d.y;
    s.sd_z[i] = d.z;
    s.s_tmax[i] = i % 3 == 0 ? kInf : 1.0f;
  }
  ASSERT_TRUE(rt::gather_static_tile(*sc, TriangleTest::kFast, shadow_bound(s), 0.0f, objects, tile));
  const std::uint64_t count = rt::occluded_static_tile(tile, 1, s, counters);
  const std::size_t blocked = expect_single_ray_occlusion(*sc, s);
  EXPECT_EQ(count, blocked);
  EXPECT_GT(blocked, 5u);
  EXPECT_LT(blocked, s.shadow_count - 5);
}

// A tile's cone (static_tiles.h TileCone) never drops a triangle that a
// ray inside it hits, by either triangle test, nor the box of a triangle
// it keeps: random cones of four or
// eight corner directions from apexes near and far from the origin,
// triangles about and beside them, and rays mixed from the corners (as a
// tile's pixel rays are). It drops most triangles beside the cone, and the
// half of a ground quad across the diagonal from a narrow cone.
TEST(StaticTiles, TheTileConeNeverDropsATriangleARayHits) {
  std::mt19937 g(19);
  const auto signed_unit = [&] { return 2.0f * unit(g) - 1.0f; };
  const auto random_vec = [&] { return Vec3(signed_unit(), signed_unit(), signed_unit()); };
  std::size_t tried = 0, hit = 0, dropped = 0;
  for (const float offset : {0.0f, 40.0f, 3000.0f}) {
    for (int c = 0; c < 60; ++c) {
      const Vec3 apex = offset * random_vec() + random_vec();
      const Vec3 centre = glm::normalize(random_vec() + Vec3(0.0f, 0.0f, 1e-3f));
      const Vec3 u = glm::normalize(glm::cross(centre, std::fabs(centre.z) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0)));
      const Vec3 v = glm::cross(centre, u);
      const float spread = 0.002f + 0.05f * unit(g);
      const int count = c % 2 == 0 ? 4 : 8;
      Vec3 corners[8];
      for (int i = 0; i < count; ++i) {
        const float x = (i & 1) ? 1.0f : -1.0f, y = (i & 2) ? 1.0f : -1.0f, z = (i & 4) ? 1.3f : 1.0f;
        corners[i] = (z * (1.0f + unit(g))) * (centre + spread * (x * u + y * v));
      }
      const rt::TileCone cone(apex, corners, count);
      for (int trial = 0; trial < 200; ++trial) {
        // A point along a mixed ray, and a triangle about it or beside it.
        Vec3 mixed(0.0f);
        float weight = 0.0f;
        for (int i = 0; i < count; ++i) {
          const float w = unit(g) * unit(g);
          mixed += w * glm::normalize(corners[i]);
          weight += w;
        }
        mixed /= weight;
        const float t = 0.5f + 50.0f * unit(g);
        const Vec3 at = apex + t * mixed;
        const float size = t * spread * (0.05f + 3.0f * unit(g) * unit(g));
        const Vec3 shift = 4.0f * t * spread * unit(g) * random_vec();
        const Vec3 p0 = at + shift + size * random_vec(), p1 = at + shift + size * random_vec(),
                   p2 = at + shift + size * random_vec();
        const bool missed = cone.misses(p0, p1, p2);
        ++tried;
        if (missed) ++dropped;
        // As a FrustumCuller of one group: the same answer, and the
        // triangle's box is reached whenever the triangle is.
        Aabb box = Aabb::empty();
        for (const Vec3& p : {p0, p1, p2}) box.extend(p);
        EXPECT_EQ(cone.reached(p0, p1, p2, ~std::uint64_t{0}), missed ? 0u : 1u);
        if (!missed) {
          EXPECT_EQ(cone.box_reached(box, ~std::uint64_t{0}), 1u);
        }
        for (int r = 0; r < 24; ++r) {
          Vec3 d(0.0f);
          for (int i = 0; i < count; ++i) d += unit(g) * glm::normalize(corners[i]);
          if (r < count) d = glm::normalize(corners[r]);  // the corner rays themselves
          Ray ray;
          ray.origin = apex;
          ray.direction = glm::normalize(d);
          rt::TriangleHit h;
          const bool fast = rt::intersect_triangle_fast(ray, ray.t_max, p0, p1, p2, h);
          const bool tight = rt::intersect_triangle_watertight(rt::prepare_watertight(ray), ray, ray.t_max, p0, p1, p2, h);
          if (!fast && !tight) continue;
          ++hit;
          ASSERT_FALSE(missed) << "a ray in the cone hits a dropped triangle; apex (" << apex.x << "," << apex.y << ","
                               << apex.z << ") cone " << c << " trial " << trial;
          break;
        }
      }
    }
  }
  EXPECT_GT(hit, tried / 10);
  EXPECT_GT(dropped, tried / 5) << dropped << " of " << tried;

  // A ground quad seen from above: a narrow cone on one side of its
  // diagonal drops the other half, one across the diagonal keeps both.
  const Vec3 eye(0.3f, 2.0f, 0.2f);
  const Vec3 q0(-50.0f, 0.0f, -50.0f), q1(50.0f, 0.0f, -50.0f), q2(-50.0f, 0.0f, 50.0f), q3(50.0f, 0.0f, 50.0f);
  const auto cone_at = [&](const Vec3& target) {
    Vec3 corners[4];
    for (int i = 0; i < 4; ++i) {
      corners[i] = target + Vec3((i & 1) ? 0.02f : -0.02f, 0.0f, (i & 2) ? 0.02f : -0.02f) - eye;
    }
    return rt::TileCone(eye, corners, 4);
  };
  const rt::TileCone near_corner_q0 = cone_at(Vec3(-3.0f, 0.0f, -2.0f));  // below the diagonal q1-q2
  EXPECT_FALSE(near_corner_q0.misses(q0, q2, q1));
  EXPECT_TRUE(near_corner_q0.misses(q1, q2, q3));
  const rt::TileCone across = cone_at(Vec3(0.0f, 0.0f, 0.0f));  // on the diagonal
  EXPECT_FALSE(across.misses(q0, q2, q1));
  EXPECT_FALSE(across.misses(q1, q2, q3));
  // No cone drops nothing.
  EXPECT_FALSE(rt::TileCone().misses(q1, q2, q3));
}

// A checkered floor of 24 x 24 quads with a box on it (one static mesh of
// 1,164 triangles, as the demo's arena): a tile that sees a few quads
// gathers them from the mesh's tree and finds every single-ray hit and
// occlusion; a tile that sees the whole floor does not qualify.
TEST(StaticTiles, FloorCellsFindTheSingleRayHits) {
  rt::StaticMeshDesc floor;
  constexpr int kQuads = 24;
  for (int z = 0; z <= kQuads; ++z) {
    for (int x = 0; x <= kQuads; ++x) floor.positions.push_back(Vec3(x - 12.0f, 0.0f, z - 12.0f));
  }
  const auto at = [](int x, int z) { return static_cast<std::uint32_t>(z * (kQuads + 1) + x); };
  for (int z = 0; z < kQuads; ++z) {
    for (int x = 0; x < kQuads; ++x) {
      floor.triangles.push_back({at(x, z), at(x, z + 1), at(x + 1, z)});
      floor.triangles.push_back({at(x + 1, z), at(x, z + 1), at(x + 1, z + 1)});
    }
  }
  // A box standing on the floor at x, z in [0.25, 0.75], 0.5 high.
  const std::uint32_t b0 = static_cast<std::uint32_t>(floor.positions.size());
  for (int i = 0; i < 8; ++i) {
    floor.positions.push_back(Vec3(i & 1 ? 0.75f : 0.25f, i & 2 ? 0.5f : 0.0f, i & 4 ? 0.75f : 0.25f));
  }
  const std::array<std::array<std::uint32_t, 4>, 6> faces = {{{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                                               {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}}};
  for (const auto& f : faces) {
    floor.triangles.push_back({b0 + f[0], b0 + f[1], b0 + f[2]});
    floor.triangles.push_back({b0 + f[0], b0 + f[2], b0 + f[3]});
  }
  rt::Scene sc;
  ASSERT_TRUE(sc.add_static_mesh(floor).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(sc.prepare_frame(rt::FrameOptions{}, jobs).ok());
  const std::vector<std::uint32_t> objects = {0};

  // Looking down at the box from above, every direction of one sign per
  // axis (the tile bound culls along an axis only then): the tile sees the
  // box and a few quads.
  rt::TileScratch s;
  const auto camera = camera_tile(Vec3(1.6f, 2.0f, 1.2f), Vec3(0.5f, 0.0f, 0.5f), 12.0f, 29, 21, s);
  rt::StaticTile tile;
  const rt::RayBound bound = camera_bound(camera, s);
  ASSERT_TRUE(rt::gather_static_tile(sc, TriangleTest::kFast, bound, 0.0f, objects, tile));
  EXPECT_GE(tile.triangles.size(), 14u) << "the box and the quad under it";
  EXPECT_LE(tile.triangles.size(), rt::kMaxStaticTileTriangles);
  EXPECT_TRUE(std::is_sorted(tile.triangles.begin(), tile.triangles.end(),
                             [](const rt::StaticTriangle& a, const rt::StaticTriangle& b) { return a.triangle < b.triangle; }));
  rt::TraversalCounters counters;
  rt::intersect_static_tile(tile, camera, s, counters);
  std::size_t box_hits = 0, floor_hits = 0;
  for (std::size_t k = 0; k < s.lanes; ++k) {
    if (!s.hit(k)) continue;
    (s.triangle[k] >= 2u * kQuads * kQuads ? box_hits : floor_hits) += 1;
  }
  EXPECT_GT(box_hits, 50u);
  EXPECT_GT(floor_hits, 50u);
  expect_single_ray_hits(sc, camera, s);
  // Gathered within the tile's cone, as trace_primary gathers: fewer
  // triangles, the same hits.
  {
    const std::size_t by_boxes = tile.triangles.size();
    ASSERT_TRUE(rt::gather_static_tile(sc, TriangleTest::kFast, bound, 0.0f, objects, tile,
                                       rt::camera_tile_cone(camera, s.tile)));
    EXPECT_LT(tile.triangles.size(), by_boxes);
    rt::intersect_static_tile(tile, camera, s, counters);
    expect_single_ray_hits(sc, camera, s);
    if (HasFatalFailure()) return;
  }

  // Shadow rays from the floor pixels to a point light: the box shadows
  // some of them.
  const Vec3 light(0.5f, 2.0f, -1.5f);  // the box shadows the floor toward +z, not toward +x
  const auto set_ray = [&](std::size_t i, const Vec3& from, const Vec3& to) {
    s.so_x[i] = from.x;
    s.so_y[i] = from.y;
    s.so_z[i] = from.z;
    s.sd_x[i] = to.x - from.x;
    s.sd_y[i] = to.y - from.y;
    s.sd_z[i] = to.z - from.z;
  };
  // The tile's occlusion agrees with the single rays', and the box blocks
  // some of them, not all.
  const auto expect_static_occlusion = [&]() {
    std::fill(s.lit.begin(), s.lit.end(), std::uint8_t{0b11});
    ASSERT_TRUE(rt::gather_static_tile(sc, TriangleTest::kFast, shadow_bound(s), 0.0f, objects, tile));
    const std::uint64_t count = rt::occluded_static_tile(tile, 1, s, counters);
    const std::size_t blocked = expect_single_ray_occlusion(sc, s);
    EXPECT_EQ(count, blocked);
    EXPECT_GT(blocked, 10u);
    EXPECT_LT(blocked, s.shadow_count - 10);
  };
  s.shadow_count = 0;
  for (std::size_t k = 0; k < s.lanes; ++k) {
    if (!s.hit(k) || s.triangle[k] >= 2u * kQuads * kQuads) continue;
    const Vec3 p = camera.eye() + s.t[k] * Vec3(s.dir_x[k], s.dir_y[k], s.dir_z[k]) + Vec3(0.0f, 1e-4f, 0.0f);
    const std::size_t i = s.shadow_count++;
    s.shadow_pixel[i] = static_cast<std::uint32_t>(k);
    set_ray(i, p, light);
    s.s_tmax[i] = 1.0f;
  }
  ASSERT_GT(s.shadow_count, 50u);
  for (std::size_t i = s.shadow_count; i < s.shadow_count + 8; ++i) {  // the spare group the arithmetic reads
    s.so_x[i] = s.so_y[i] = s.so_z[i] = s.sd_x[i] = s.sd_y[i] = 0.0f;
    s.sd_z[i] = s.s_tmax[i] = 1.0f;
  }
  expect_static_occlusion();
  if (HasFatalFailure()) return;

  // The same points seen from the light, as the renderer traces a point
  // light's rays: one origin, so the tile takes the common-origin test,
  // which must block exactly the single rays that are blocked.
  for (std::size_t i = 0; i < s.shadow_count; ++i) set_ray(i, light, Vec3(s.so_x[i], s.so_y[i], s.so_z[i]));
  s.shadows_from_point = true;
  s.shadow_origin = light;
  expect_static_occlusion();
  if (HasFatalFailure()) return;

  // The whole floor from afar reaches far more triangles than a tile may
  // hold: the tile's large packets walk the floor's tree with their group
  // frusta instead, and find the single rays' hits.
  rt::TileScratch w;
  const auto wide = camera_tile(Vec3(0.0f, 20.0f, 20.0f), Vec3(0.0f), 60.0f, 16, 16, w);
  EXPECT_FALSE(rt::gather_static_tile(sc, TriangleTest::kFast, camera_bound(wide, w), 0.0f, objects, tile));
  w.prepare(Tile{0, 0, 16, 16, 0}, rt::plan_for_packet_rays(256));
  rt::generate_camera_rays(wide, w);
  rt::TraversalCounters walked;
  rt::trace_primary(sc, wide, TriangleTest::kFast, w, walked);
  EXPECT_GT(walked.node_visits, 0u);
  const std::vector<std::size_t> wide_hits = expect_single_ray_hits(sc, wide, w);
  EXPECT_GT(wide_hits[0], 100u);
}

}  // namespace
}  // namespace sinew
