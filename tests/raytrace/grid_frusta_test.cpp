// Grid frusta (cull/grid_frusta.h) of camera packets never cull a group
// whose ray hits a triangle or enters a box, by either triangle test, for
// random cameras, image sizes and regions (1 to 8 columns, 1 to 8 rows of
// 4x2-pixel blocks, partial lane masks), near the origin and thousands of
// units from it; they cull most triangles beside a group; and a grid that
// does not fit, or a lane behind the camera, culls nothing.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/cull/grid_frusta.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "runtime/math/aabb.h"
#include "runtime/math/float8.h"
#include "runtime/math/ray.h"
#include "tests/support/slab_test.h"

namespace sinew {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }
Vec3 random_vec(std::mt19937& g) { return Vec3(2.0f * unit(g) - 1.0f, 2.0f * unit(g) - 1.0f, 2.0f * unit(g) - 1.0f); }

bool hits(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  rt::TriangleHit h;
  if (rt::intersect_triangle_fast(ray, ray.t_max, p0, p1, p2, h)) return true;
  return rt::intersect_triangle_watertight(rt::prepare_watertight(ray), ray, ray.t_max, p0, p1, p2, h);
}

// Whether the ray's points at t >= 0 meet the box, in double.
bool enters(const Ray& ray, const Aabb& box) {
  return testing_support::ray_enters_box(ray.origin, ray.direction, 0.0, std::numeric_limits<double>::infinity(), box);
}

// A region of `columns` x `rows` blocks at pixel (x0, y0): each group's
// directions as generate_camera_rays computes them (render/stages/tile_stages.h).
struct Region {
  int columns = 0, rows = 0;
  std::vector<std::array<std::array<float, 8>, 3>> d;  // [group][axis][lane]
  std::vector<std::uint32_t> lanes;
  const float (&q(int g) const)[3][8] { return reinterpret_cast<const float(&)[3][8]>(d[static_cast<std::size_t>(g)]); }
};

Region make_region(const rt::PinholeCamera& camera, int x0, int y0, int columns, int rows, bool partial,
                   std::mt19937& g) {
  Region r;
  r.columns = columns;
  r.rows = rows;
  const int groups = columns * rows;
  r.d.resize(static_cast<std::size_t>(groups));
  r.lanes.resize(static_cast<std::size_t>(groups));
  for (int group = 0; group < groups; ++group) {
    alignas(32) float xs[8], ys[8];
    for (int lane = 0; lane < 8; ++lane) {
      xs[lane] = static_cast<float>(x0 + 4 * (group % columns) + lane % 4) + 0.5f;
      ys[lane] = static_cast<float>(y0 + 2 * (group / columns) + lane / 4) + 0.5f;
    }
    const Vec3x8 d = camera.directions_at(Float8::load(xs), Float8::load(ys));
    alignas(32) float out[3][8];
    d.x.store(out[0]);
    d.y.store(out[1]);
    d.z.store(out[2]);
    for (int a = 0; a < 3; ++a) {
      for (int lane = 0; lane < 8; ++lane) r.d[static_cast<std::size_t>(group)][static_cast<std::size_t>(a)][static_cast<std::size_t>(lane)] = out[a][lane];
    }
    r.lanes[static_cast<std::size_t>(group)] = partial ? (g() & 0xFFu) | 1u : 0xFFu;
  }
  return r;
}

bool build(rt::GridFrusta& grid, const rt::PinholeCamera& camera, const Region& r) {
  return grid.build(camera.eye(), camera.forward(), camera.right(), camera.up(), r.columns * r.rows, r.columns,
                    [&](int g) -> const float (&)[3][8] { return r.q(g); },
                    [&](int g) { return r.lanes[static_cast<std::size_t>(g)]; });
}

TEST(GridFrusta, NeverCullAGroupWhoseRayHitsOrEnters) {
  std::mt19937 g(17);
  int tried = 0, hit = 0, culled_groups = 0, group_trials = 0, boxes_entered = 0;
  for (const float offset : {0.0f, 70.0f, 3000.0f}) {
    for (int view = 0; view < 40; ++view) {
      const Vec3 eye = offset * random_vec(g) + random_vec(g);
      const Vec3 target = eye + random_vec(g) + Vec3(0.0f, 0.0f, 0.01f);
      const float fov = 5.0f + 150.0f * unit(g);
      const int width = 16 + static_cast<int>(g() % 2000), height = 16 + static_cast<int>(g() % 2000);
      const auto made = rt::PinholeCamera::create({eye, target, Vec3(0, 1, 0), fov}, width, height);
      if (!made.ok()) continue;
      const rt::PinholeCamera& camera = made.value();
      const int columns = 1 + static_cast<int>(g() % 8), rows = 1 + static_cast<int>(g() % 8);
      const int x0 = static_cast<int>(g() % static_cast<unsigned>(std::max(1, width - 4 * columns)));
      const int y0 = static_cast<int>(g() % static_cast<unsigned>(std::max(1, height - 2 * rows)));
      const Region r = make_region(camera, x0, y0, columns, rows, view % 3 == 0, g);
      rt::GridFrusta grid;
      if (!build(grid, camera, r)) continue;  // wide views: rays far off the forward axis
      const int groups = columns * rows;
      const std::uint64_t all = groups == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << groups) - 1u;
      for (int trial = 0; trial < 200; ++trial) {
        // About a lane's ray, at a random size, shifted by up to the region's width.
        const int group = static_cast<int>(g() % static_cast<unsigned>(groups));
        const int lane = static_cast<int>(g() % 8);
        const Vec3 d(r.q(group)[0][lane], r.q(group)[1][lane], r.q(group)[2][lane]);
        const float t = 0.05f + 40.0f * unit(g);
        const Vec3 at = eye + t * d;
        const float pixel = 2.0f * std::tan(0.5f * fov * 3.14159265f / 180.0f) / static_cast<float>(height);
        const float width_there = 16.0f * pixel * t;
        const float size = width_there * (0.002f + 0.3f * unit(g) * unit(g));
        const Vec3 shift = 1.5f * width_there * unit(g) * random_vec(g);
        const Vec3 p0 = at + shift + size * random_vec(g), p1 = at + shift + size * random_vec(g),
                   p2 = at + shift + size * random_vec(g);
        const std::uint64_t reached = grid.reached(p0, p1, p2, all);
        const Vec3 half = size * Vec3(unit(g), unit(g), unit(g));
        const Aabb box{at + shift - half, at + shift + half};
        const std::uint64_t box_reached = grid.box_reached(box, all);
        // The triangle's own box (a leaf's box, raytrace/scene/leaf_boxes.h)
        // reaches every group the triangle does.
        const Aabb around{glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2))};
        ASSERT_EQ(reached & ~grid.box_reached(around, all), 0u)
            << "groups reach the triangle but not its box; view " << view << " offset " << offset << " trial " << trial;
        ++tried;
        for (int k = 0; k < groups; ++k) {
          ++group_trials;
          if (!(reached >> k & 1u)) ++culled_groups;
          for (int l = 0; l < 8; ++l) {
            if (!(r.lanes[static_cast<std::size_t>(k)] >> l & 1u)) continue;
            Ray ray;
            ray.origin = eye;
            ray.direction = Vec3(r.q(k)[0][l], r.q(k)[1][l], r.q(k)[2][l]);
            ray.t_min = 0.0f;
            ray.t_max = kInf;
            if (hits(ray, p0, p1, p2)) {
              ++hit;
              ASSERT_NE(reached >> k & 1u, 0u) << "group " << k << " lane " << l << " hits a culled triangle; view "
                                               << view << " offset " << offset << " trial " << trial;
            }
            if (enters(ray, box)) {
              ++boxes_entered;
              ASSERT_NE(box_reached >> k & 1u, 0u) << "group " << k << " lane " << l << " enters a culled box; view "
                                                   << view << " offset " << offset << " trial " << trial;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(tried, 10000);
  EXPECT_GT(hit, tried / 5);
  EXPECT_GT(boxes_entered, tried / 5);
  // Most groups of a region miss a triangle beside one of them: the test has teeth.
  EXPECT_GT(culled_groups, group_trials / 2) << culled_groups << " of " << group_trials;
}

TEST(GridFrusta, GridsThatDoNotFitOrLanesBehindCullNothing) {
  std::mt19937 g(3);
  const auto camera = rt::PinholeCamera::create({Vec3(0.0f), Vec3(0, 0, -1), Vec3(0, 1, 0), 40.0f}, 256, 256).value();
  rt::GridFrusta grid;
  const Region wide = make_region(camera, 0, 0, 9, 2, false, g);
  EXPECT_FALSE(build(grid, camera, wide));
  const Region tall = make_region(camera, 0, 0, 1, 9, false, g);
  EXPECT_FALSE(build(grid, camera, tall));
  Region behind = make_region(camera, 100, 100, 8, 8, false, g);
  ASSERT_TRUE(build(grid, camera, behind));
  // A triangle far to the side is culled for every group...
  const Vec3 q0(50.0f, 0.0f, -1.0f), q1(51.0f, 0.0f, -1.0f), q2(50.0f, 1.0f, -1.0f);
  EXPECT_EQ(grid.reached(q0, q1, q2, ~std::uint64_t{0}), 0u);
  // ...but not once a lane of the last group looks backwards, nor after reset().
  behind.d[63][2][3] = 1.0f;
  EXPECT_FALSE(build(grid, camera, behind));
  EXPECT_EQ(grid.reached(q0, q1, q2, 0xFFu), 0xFFu);
  ASSERT_TRUE(build(grid, camera, make_region(camera, 100, 100, 4, 8, false, g)));
  grid.reset();
  EXPECT_EQ(grid.box_reached(Aabb{q0, q1 + Vec3(0.0f, 1.0f, 0.0f)}, 0x3u), 0x3u);
}

// reached8 (a leaf's triangles eight at a time, traverse/large_packet.cpp)
// decides each triangle and group as reached() does, for random batches of
// one to eight triangles about the region's rays, random lanes of the
// batch and random groups, near the origin and far from it; and reaches
// every group of the lanes given when the grid is off.
TEST(GridFrusta, ReachedEightAtATimeDecidesAsOneAtATime) {
  std::mt19937 g(29);
  int compared = 0, culled = 0, some_groups = 0;
  for (const float offset : {0.0f, 70.0f, 3000.0f}) {
    for (int view = 0; view < 30; ++view) {
      const Vec3 eye = offset * random_vec(g) + random_vec(g);
      const Vec3 target = eye + random_vec(g) + Vec3(0.0f, 0.0f, 0.01f);
      const float fov = 5.0f + 100.0f * unit(g);
      const int size = 64 + static_cast<int>(g() % 1500);
      const auto made = rt::PinholeCamera::create({eye, target, Vec3(0, 1, 0), fov}, size, size);
      if (!made.ok()) continue;
      const rt::PinholeCamera& camera = made.value();
      const int columns = 1 + static_cast<int>(g() % 8), rows = 1 + static_cast<int>(g() % 8);
      const Region r = make_region(camera, static_cast<int>(g() % 32), static_cast<int>(g() % 32), columns, rows,
                                   view % 3 == 0, g);
      rt::GridFrusta grid;
      if (!build(grid, camera, r)) continue;
      const int groups = columns * rows;
      const float pixel = 2.0f * std::tan(0.5f * fov * 3.14159265f / 180.0f) / static_cast<float>(size);
      for (int batch = 0; batch < 60; ++batch) {
        rt::TriangleLanes8 t;
        for (int i = 0; i < 8; ++i) {
          const int group = static_cast<int>(g() % static_cast<unsigned>(groups));
          const int lane = static_cast<int>(g() % 8);
          const Vec3 d(r.q(group)[0][lane], r.q(group)[1][lane], r.q(group)[2][lane]);
          const float depth = 0.05f + 40.0f * unit(g);
          const float width = 8.0f * pixel * depth;
          const Vec3 at = eye + depth * d + 2.0f * width * unit(g) * random_vec(g);
          for (int k = 0; k < 3; ++k) {
            const Vec3 p = at + width * unit(g) * random_vec(g);
            t.p[k][0][i] = p.x;
            t.p[k][1][i] = p.y;
            t.p[k][2][i] = p.z;
          }
        }
        const int n = 1 + static_cast<int>(g() % 8);
        const std::uint32_t lanes = ((1u << n) - 1u) & (batch % 3 == 0 ? g() | 1u : ~0u);
        const std::uint64_t all = groups == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << groups) - 1u;
        const std::uint64_t want_groups = batch % 2 == 0 ? all : all & (std::uint64_t{g()} << 32 | g());
        std::uint64_t out[8];
        grid.reached8(t, lanes, want_groups, out);
        for (int i = 0; i < 8; ++i) {
          const std::uint64_t want =
              (lanes >> i & 1u) ? grid.reached(t.corner(0, i), t.corner(1, i), t.corner(2, i), want_groups) : 0u;
          ASSERT_EQ(out[i], want) << "triangle " << i << " of batch " << batch << " view " << view << " offset "
                                  << offset;
          if (!(lanes >> i & 1u)) continue;
          ++compared;
          if (want == 0) ++culled;
          if (want != 0 && want != want_groups) ++some_groups;
        }
      }
    }
  }
  EXPECT_GT(compared, 5000);
  EXPECT_GT(culled, compared / 10) << culled << " of " << compared;
  EXPECT_GT(some_groups, compared / 10) << some_groups << " of " << compared;
  // Off: every group given, for the lanes given only.
  rt::GridFrusta off;
  rt::TriangleLanes8 t{};
  std::uint64_t out[8];
  off.reached8(t, 0x5u, 0x30u, out);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(out[i], i == 0 || i == 2 ? 0x30u : 0u) << i;
}

}  // namespace
}  // namespace sinew
