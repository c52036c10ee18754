// The coherent-ray machinery of render/: interval bounds on ray sets never
// cull a box some ray enters (against a double-precision slab test), the
// packet cull keeps every object a lane reaches, culled packets find the
// single-ray hits, the SoA stages reproduce the scalar camera and surface
// code, and the renderer matches single rays and brute force for packets
// that straddle tile and image edges, cameras inside a character and rays
// starting inside bone boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "raytrace/accel/top_level.h"
#include "raytrace/camera/camera.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/render/renderer.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/traverse/packet_traversal.h"
#include "raytrace/traverse/static_tiles.h"
#include "raytrace/traverse/traversal.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/jobs/job_system.h"
#include "runtime/math/float8.h"
#include "runtime/memory/line_aligned.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"
#include "tests/support/slab_test.h"

namespace sinew {
namespace {

using rt::TriangleTest;
constexpr TriangleTest kTests[] = {TriangleTest::kFast, TriangleTest::kWatertight};
constexpr float kInf = std::numeric_limits<float>::infinity();

float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }

// Two mannequins on a ground quad, one idling inside its pose space, one
// kicking out of it (its escaped triangles go through the fallback).
std::unique_ptr<rt::Scene> make_scene() {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t instance = scene->add_instance(character).value();
    const Affine3 place = Affine3::translation(Vec3(0.9f * static_cast<float>(i) - 0.45f, 0.0f, 0.0f));
    EXPECT_TRUE(scene
                    ->set_bones(instance, testing_support::clip_pose(m.model, i == 1 ? "kick" : "idle",
                                                                     i == 1 ? 0.4 : 0.3, place))
                    .ok());
  }
  rt::StaticMeshDesc ground;
  ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  EXPECT_TRUE(scene->add_static_mesh(ground).ok());
  JobSystem jobs(2);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return scene;
}

const rt::Scene& scene() {
  static const std::unique_ptr<rt::Scene> s = make_scene();
  return *s;
}

// Whether the ray enters `box` within [t0, t1], in double precision.
bool enters(const Aabb& box, const Vec3& o, const Vec3& d, double t0, double t1) {
  return testing_support::ray_enters_box(o, d, t0, t1, box);
}

TEST(RayBound, NeverCullsABoxThatARayEnters) {
  std::mt19937 g(7);
  std::size_t entered = 0, culled = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    alignas(32) float o[3][8], d[3][8], t0[8], t1[8];
    const bool shared = trial % 2 == 0;
    const Vec3 base(unit(g) * 4 - 2, unit(g) * 4 - 2, unit(g) * 4 - 2);
    const Vec3 aim(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f);
    for (int lane = 0; lane < 8; ++lane) {
      for (int a = 0; a < 3; ++a) {
        o[a][lane] = shared ? base[a] : base[a] + 0.3f * (unit(g) - 0.5f);
        // Coherent around `aim`, sometimes spread over both signs, sometimes
        // exactly zero on an axis.
        const float spread = trial % 5 == 0 ? 2.0f : 0.1f;
        d[a][lane] = (trial % 7 == 0 && a == 1) ? 0.0f : aim[a] + spread * (unit(g) - 0.5f);
      }
      t0[lane] = trial % 3 == 0 ? unit(g) : 0.0f;
      t1[lane] = trial % 4 == 0 ? kInf : 1.0f + 4.0f * unit(g);
    }
    const std::uint32_t lanes = trial % 6 == 0 ? (g() & 0xFFu) | 1u : 0xFFu;
    rt::RayBound bound;
    const float* const op[3] = {o[0], o[1], o[2]};
    const float* const dp[3] = {d[0], d[1], d[2]};
    bound.add_lanes(op, dp, t0, t1, lanes);
    const rt::RayBound::Test test = bound.test();
    for (int b = 0; b < 8; ++b) {
      const Vec3 c(unit(g) * 6 - 3, unit(g) * 6 - 3, unit(g) * 6 - 3);
      const Vec3 e(unit(g) * 0.5f, unit(g) * 0.5f, unit(g) * 0.5f);
      const Aabb box{c - e, c + e};
      bool any = false;
      for (int lane = 0; lane < 8; ++lane) {
        if (!(lanes >> lane & 1u)) continue;
        any = any || enters(box, Vec3(o[0][lane], o[1][lane], o[2][lane]), Vec3(d[0][lane], d[1][lane], d[2][lane]),
                            t0[lane], t1[lane]);
      }
      const bool may = test.may_enter(box, 0.0f);
      if (any) {
        ++entered;
        ASSERT_TRUE(may) << "trial " << trial << " box " << b << ": a ray enters a culled box";
      } else if (!may) {
        ++culled;
      }
    }
  }
  // The counts of this fixed seed: about 1,800 boxes entered, and most of
  // the others culled.
  EXPECT_GT(entered, 1000u);
  EXPECT_GT(culled, 100000u) << "the bound should cull most boxes no ray enters";
}

// A point light's shadow rays that end just above a wide flat ground (a
// floor thousands of units across, as the editor's ground quad is): the
// ground is culled once their ends clear it by the traversal's own slack
// and the bound's rounding on the height axis, not at the scale of the
// ground's width. Never culled where a lane's own box clip (the traversal's
// float slab test with its slack) enters the box.
TEST(RayBound, WideFlatBoxesAreCulledByTheirHeightNotTheirWidth) {
  std::mt19937 g(41);
  std::size_t clipped = 0, pushed_sets = 0, pushed_culled = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const float width = trial % 3 == 0 ? 10.0f : trial % 3 == 1 ? 2000.0f : 50000.0f;
    const float ground = trial % 2 == 0 ? 0.0017f : -1.97f;
    const Aabb box{Vec3(-width, -width, ground), Vec3(width, width, ground)};
    const Vec3 light(100.0f * (unit(g) - 0.5f), -200.0f * unit(g), 50.0f + 400.0f * unit(g));
    const Vec3 centre(300.0f * (unit(g) - 0.5f), 300.0f * (unit(g) - 0.5f), ground);
    // Ends at the renderer's push above the ground (shadow_ray_from_light),
    // or at heights around the traversal's slack, above and below.
    const bool pushed = trial % 2 == 0;
    alignas(32) float d[3][8], t0[8], t1[8];
    const float slack = rt::kFrameRelativeSlack * (rt::detail::max_abs(light) + 600.0f + width);
    for (int lane = 0; lane < 8; ++lane) {
      Vec3 end;
      if (pushed) {
        rt::SurfacePoint surface;
        surface.position = centre + Vec3(4.0f * unit(g), 4.0f * unit(g), 0.0f);
        surface.geometric_normal = Vec3(0.0f, 0.0f, 1.0f);
        // surface_at's bound: gamma(7) of the triangle's corners, the ground's.
        surface.error = Vec3(7.0f * 0x1.0p-24f / (1.0f - 7.0f * 0x1.0p-24f) * rt::detail::max_abs(box));
        const Ray ray = rt::shadow_ray_from_light(surface, light - surface.position, light);
        end = light + ray.direction;
      } else {
        end = centre + Vec3(4.0f * unit(g), 4.0f * unit(g), ground + slack * (8.0f * unit(g) - 3.0f) - ground);
      }
      for (int a = 0; a < 3; ++a) d[a][lane] = end[a] - light[a];
      t0[lane] = 0.0f;
      t1[lane] = 1.0f;
    }
    rt::RayBound bound;
    const float* const dp[3] = {d[0], d[1], d[2]};
    bound.add_lanes(light, dp, 0.0f, 1.0f, 0xFFu);
    const float grow = bound.world_slack_bound(rt::detail::max_abs(box));
    const bool may = bound.test().may_enter(box, grow);
    bool any = false;
    for (int lane = 0; lane < 8; ++lane) {
      const Vec3 dir(d[0][lane], d[1][lane], d[2][lane]);
      const float eps = rt::kFrameRelativeSlack * (rt::detail::max_abs(light) + t1[lane] * rt::detail::max_abs(dir) +
                                                   rt::detail::max_abs(box));
      float a = t0[lane], b = t1[lane];
      any = any || rt::per_lane::clip_to_box<float>(box, eps, light, dir, Vec3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z),
                                           a, b);
    }
    if (any) {
      ++clipped;
      ASSERT_TRUE(may) << "trial " << trial << ": a lane's clip enters a culled box";
    }
    if (pushed && !any) {
      ++pushed_sets;
      if (!may) ++pushed_culled;
    }
  }
  EXPECT_GT(clipped, 200u) << "the heights should straddle the slack";
  // Of the pushed sets no lane's clip enters, this seed culls 1,330 of
  // 1,333; with the width in the height's margin it culled half, and with
  // the scene's reach in the slack of rays that end at t = 1, fewer.
  EXPECT_GT(pushed_sets, 1000u);
  EXPECT_GE(pushed_culled * 100, pushed_sets * 95) << pushed_culled << " of " << pushed_sets;
}

TEST(RayBound, NonFiniteRaysCullNothing) {
  alignas(32) float o[3][8] = {}, d[3][8] = {}, t0[8] = {}, t1[8];
  for (int lane = 0; lane < 8; ++lane) {
    d[2][lane] = 1.0f;
    t1[lane] = 1.0f;
  }
  o[0][3] = std::numeric_limits<float>::quiet_NaN();
  rt::RayBound bound;
  const float* const op[3] = {o[0], o[1], o[2]};
  const float* const dp[3] = {d[0], d[1], d[2]};
  bound.add_lanes(op, dp, t0, t1, 0xFFu);
  EXPECT_TRUE(bound.test().may_enter(Aabb{Vec3(100.0f), Vec3(101.0f)}, 0.0f));
}

// Groups added with one shared origin and parameter range bound exactly
// what the same rays added lane by lane bound (min and max are exact), in
// any mix with groups of their own origins.
TEST(RayBound, SharedOriginGroupsBoundAsTheirLanesDo) {
  std::mt19937 g(23);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    rt::RayBound mixed, by_lane;
    const int groups = 1 + trial % 5;
    for (int k = 0; k < groups; ++k) {
      alignas(32) float o[3][8], d[3][8], t0[8], t1[8];
      const bool shared = (trial + k) % 3 != 0;
      const Vec3 apex(unit(g) * 8 - 4, unit(g) * 8 - 4, unit(g) * 8 - 4);
      const float shared_t0 = trial % 4 == 0 ? unit(g) : 0.0f;
      const float shared_t1 = trial % 5 == 0 ? kInf : 1.0f + unit(g);
      for (int lane = 0; lane < 8; ++lane) {
        for (int a = 0; a < 3; ++a) {
          o[a][lane] = shared ? apex[a] : apex[a] + unit(g) - 0.5f;
          d[a][lane] = unit(g) - 0.5f;
        }
        t0[lane] = shared ? shared_t0 : 0.5f * unit(g);
        t1[lane] = shared ? shared_t1 : 1.0f + unit(g);
      }
      const std::uint32_t lanes = trial % 7 == 0 ? (g() & 0xFFu) | 0x10u : 0xFFu;
      const float* const op[3] = {o[0], o[1], o[2]};
      const float* const dp[3] = {d[0], d[1], d[2]};
      if (shared) {
        mixed.add_lanes(apex, dp, shared_t0, shared_t1, lanes);
      } else {
        mixed.add_lanes(op, dp, t0, t1, lanes);
      }
      by_lane.add_lanes(op, dp, t0, t1, lanes);
    }
    ASSERT_EQ(mixed.world_slack_bound(10.0f), by_lane.world_slack_bound(10.0f)) << "trial " << trial;
    const rt::RayBound::Test a = mixed.test(), b = by_lane.test();
    for (int box = 0; box < 16; ++box) {
      const Vec3 c(unit(g) * 10 - 5, unit(g) * 10 - 5, unit(g) * 10 - 5);
      const Vec3 e(unit(g), unit(g), unit(g));
      const Aabb cell{c - e, c + e};
      ASSERT_EQ(a.may_enter(cell, 0.01f), b.may_enter(cell, 0.01f)) << "trial " << trial << " box " << box;
    }
  }
  // Many groups from one origin at once (a tile's camera rays, a point
  // light's run of shadow rays) bound what they bound one by one.
  for (int trial = 0; trial < 500; ++trial) {
    const int groups = 1 + trial % 9;
    const Vec3 apex(unit(g) * 8 - 4, unit(g) * 8 - 4, unit(g) * 8 - 4);
    const float t0 = trial % 3 == 0 ? unit(g) : 0.0f, t1 = trial % 4 == 0 ? kInf : 1.0f + unit(g);
    std::vector<float> dx(8 * groups), dy(8 * groups), dz(8 * groups);
    std::vector<std::uint8_t> lanes(groups);
    for (int k = 0; k < groups; ++k) {
      lanes[k] = static_cast<std::uint8_t>(trial % 5 == 0 ? g() & 0xFFu : 0xFFu);  // some groups empty
      for (int lane = 0; lane < 8; ++lane) {
        dx[8 * k + lane] = unit(g) - 0.5f;
        dy[8 * k + lane] = unit(g) - 0.5f;
        dz[8 * k + lane] = trial % 7 == 0 ? 0.0f : unit(g) - 0.5f;
      }
    }
    const float* const d[3] = {dx.data(), dy.data(), dz.data()};
    rt::RayBound grouped, one_by_one, run, run_by_lane;
    grouped.add_groups(apex, d, t0, t1, lanes);
    const int rays = 8 * groups - trial % 8;
    run.add_run(apex, d, t0, t1, static_cast<std::size_t>(rays));
    for (int k = 0; k < groups; ++k) {
      const float* const dk[3] = {dx.data() + 8 * k, dy.data() + 8 * k, dz.data() + 8 * k};
      one_by_one.add_lanes(apex, dk, t0, t1, lanes[k]);
      const int left = rays - 8 * k;
      run_by_lane.add_lanes(apex, dk, t0, t1, left >= 8 ? 0xFFu : (1u << left) - 1u);
    }
    ASSERT_EQ(grouped.empty(), one_by_one.empty()) << "trial " << trial;
    if (grouped.empty()) continue;
    ASSERT_EQ(grouped.world_slack_bound(10.0f), one_by_one.world_slack_bound(10.0f)) << "trial " << trial;
    ASSERT_EQ(run.world_slack_bound(10.0f), run_by_lane.world_slack_bound(10.0f)) << "trial " << trial;
    const rt::RayBound::Test a = grouped.test(), b = one_by_one.test(), c = run.test(), e = run_by_lane.test();
    for (int box = 0; box < 16; ++box) {
      const Vec3 centre(unit(g) * 10 - 5, unit(g) * 10 - 5, unit(g) * 10 - 5);
      const Vec3 half(unit(g), unit(g), unit(g));
      const Aabb cell{centre - half, centre + half};
      ASSERT_EQ(a.may_enter(cell, 0.01f), b.may_enter(cell, 0.01f)) << "trial " << trial << " box " << box;
      ASSERT_EQ(c.may_enter(cell, 0.01f), e.may_enter(cell, 0.01f)) << "trial " << trial << " box " << box;
    }
  }

  // A non-finite shared origin or parameter range culls nothing.
  alignas(32) float d[3][8] = {};
  for (float& z : d[2]) z = 1.0f;
  const float* const dp[3] = {d[0], d[1], d[2]};
  rt::RayBound nan_origin, nan_t;
  nan_origin.add_lanes(Vec3(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f), dp, 0.0f, 1.0f, 0xFFu);
  nan_t.add_lanes(Vec3(0.0f), dp, 0.0f, std::numeric_limits<float>::quiet_NaN(), 0xFFu);
  EXPECT_TRUE(nan_origin.test().may_enter(Aabb{Vec3(100.0f), Vec3(101.0f)}, 0.0f));
  EXPECT_TRUE(nan_t.test().may_enter(Aabb{Vec3(100.0f), Vec3(101.0f)}, 0.0f));
  // So does a non-finite direction in one of many groups.
  std::vector<float> many_x(32, 0.0f), many_y(32, 0.0f), many_z(32, 1.0f);
  many_x[19] = std::numeric_limits<float>::infinity();
  const float* const many[3] = {many_x.data(), many_y.data(), many_z.data()};
  rt::RayBound inf_direction;
  inf_direction.add_run(Vec3(0.0f), many, 0.0f, 1.0f, 32);
  EXPECT_TRUE(inf_direction.test().may_enter(Aabb{Vec3(100.0f), Vec3(101.0f)}, 0.0f));
}

// TopLevel's runs: one per character instance (its bones and fallback,
// consecutive) and one per static mesh, covering every object once, each
// run's box holding every coordinate of its members' boxes (an inverted
// one's too: the tree skips it, the flat cull tests it).
TEST(TopLevel, RunsGroupEachInstanceAndHoldTheirMembers) {
  using Kind = rt::TopLevelObject::Kind;
  const auto box = [](float lo, float hi) { return Aabb{Vec3(lo), Vec3(hi)}; };
  std::vector<rt::TopLevelObject> objects = {
      {Kind::kBone, 0, 0, box(0.0f, 1.0f)},    {Kind::kBone, 0, 1, box(-3.0f, -2.0f)},
      {Kind::kFallback, 0, 0, box(5.0f, 4.0f)},  // inverted
      {Kind::kBone, 1, 0, box(10.0f, 11.0f)},  {Kind::kBone, 1, 3, Aabb{Vec3(12.0f, 9.0f, 12.0f), Vec3(12.0f, 13.0f, 12.0f)}},
      {Kind::kStatic, 0, 0, box(-1.0f, 1.0f)}, {Kind::kStatic, 1, 0, box(2.0f, 3.0f)},
      {Kind::kBone, 2, 0, box(20.0f, 21.0f)}};
  const std::vector<rt::TopLevelObject> copy = objects;
  rt::TopLevel top;
  ASSERT_TRUE(top.build(std::move(objects), rt::KdBuildOptions{}).ok());
  const std::span<const rt::ObjectRun> runs = top.runs();
  ASSERT_EQ(runs.size(), 5u);
  const std::uint32_t firsts[5] = {0, 3, 5, 6, 7}, counts[5] = {3, 2, 1, 1, 1};
  for (std::size_t r = 0; r < runs.size(); ++r) {
    EXPECT_EQ(runs[r].first, firsts[r]) << r;
    EXPECT_EQ(runs[r].count, counts[r]) << r;
  }
  EXPECT_EQ(runs[0].box.lower, Vec3(-3.0f));
  EXPECT_EQ(runs[0].box.upper, Vec3(5.0f));
  EXPECT_EQ(runs[1].box.lower, Vec3(10.0f, 9.0f, 10.0f));
  EXPECT_EQ(runs[1].box.upper, Vec3(12.0f, 13.0f, 12.0f));
  for (const rt::ObjectRun& run : runs) {
    for (std::uint32_t i = run.first; i < run.first + run.count; ++i) {
      for (int a = 0; a < 3; ++a) {
        for (const float c : {copy[i].box.lower[a], copy[i].box.upper[a]}) {
          EXPECT_LE(run.box.lower[a], c) << i;
          EXPECT_GE(run.box.upper[a], c) << i;
        }
      }
    }
  }
}

// cull_objects tests each run's box (a character's bones, a static mesh),
// then its members', in scenes of up to kFlatCullObjects runs and walks the
// top-level tree in larger ones: both keep every object whose box a ray of
// the set enters (in double precision), and both cull most of the others.
TEST(RayBound, CullKeepsEveryObjectARayEntersWithFewAndManyObjects) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  for (const int instances : {1, 6, 70}) {
    rt::Scene scene;
    const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
    for (int i = 0; i < instances; ++i) {
      const std::uint32_t instance = scene.add_instance(character).value();
      const int row = instances > 6 ? 9 : 3;
      const Affine3 place =
          Affine3::translation(Vec3(0.9f * static_cast<float>(i % row), 0.0f, 0.9f * static_cast<float>(i / row)));
      ASSERT_TRUE(scene.set_bones(instance, testing_support::clip_pose(m.model, "idle", 0.1 * i, place)).ok());
    }
    JobSystem jobs(2);
    ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
    const std::span<const rt::TopLevelObject> objects = scene.top_level().objects();
    ASSERT_EQ(scene.top_level().runs().size(), static_cast<std::size_t>(instances));
    ASSERT_EQ(scene.top_level().runs().size() > rt::kFlatCullObjects, instances == 70);
    const Aabb world = scene.top_level().bounds();
    std::mt19937 g(5);
    std::size_t entered = 0, culled = 0;
    for (int trial = 0; trial < (instances > 6 ? 600 : 3000); ++trial) {
      alignas(32) float o[3][8], d[3][8], t0[8], t1[8];
      const Vec3 base = world.lower + Vec3(unit(g), unit(g), unit(g)) * (world.upper - world.lower);
      const Vec3 aim(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f);
      for (int lane = 0; lane < 8; ++lane) {
        for (int a = 0; a < 3; ++a) {
          o[a][lane] = trial % 2 == 0 ? base[a] : base[a] + 0.2f * (unit(g) - 0.5f);
          d[a][lane] = aim[a] + 0.05f * (unit(g) - 0.5f);
        }
        t0[lane] = 0.0f;
        t1[lane] = trial % 3 == 0 ? kInf : 0.5f * unit(g);
      }
      rt::RayBound bound;
      const float* const op[3] = {o[0], o[1], o[2]};
      const float* const dp[3] = {d[0], d[1], d[2]};
      bound.add_lanes(op, dp, t0, t1, 0xFFu);
      std::vector<std::uint32_t> kept;
      rt::cull_objects(scene, bound, kept);
      ASSERT_TRUE(std::is_sorted(kept.begin(), kept.end()));
      for (std::uint32_t object = 0; object < objects.size(); ++object) {
        bool any = false;
        for (int lane = 0; lane < 8 && !any; ++lane) {
          any = enters(objects[object].box, Vec3(o[0][lane], o[1][lane], o[2][lane]),
                       Vec3(d[0][lane], d[1][lane], d[2][lane]), t0[lane], t1[lane]);
        }
        const bool listed = std::binary_search(kept.begin(), kept.end(), object);
        if (any) {
          ++entered;
          ASSERT_TRUE(listed) << instances << " instances, trial " << trial << ": object " << object << " culled";
        } else if (!listed) {
          ++culled;
        }
      }
    }
    EXPECT_GT(entered, 500u) << instances << " instances";
    EXPECT_GT(culled, 3 * entered) << instances << " instances";
  }
}

// Random packets around the characters: culled by a bound over their rays
// (as the renderer culls a tile's) and unculled, they agree with single rays.
TEST(PacketCulling, CulledPacketsFindTheSingleRayHits) {
  const rt::Scene& s = scene();
  std::mt19937 g(11);
  const Vec3 c(0.0f, 0.9f, 0.0f);
  std::size_t hits = 0, checked = 0;
  for (int p = 0; p < 1500; ++p) {
    rt::RayPacket packet;
    // Origins: a shared far point, scattered points, or points inside the
    // characters' bone boxes.
    const Vec3 shared = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * 4.0f;
    const std::span<const rt::TopLevelObject> objects = s.top_level().objects();
    for (int lane = 0; lane < 8; ++lane) {
      Ray ray;
      if (p % 3 == 0) {
        ray.origin = shared;
      } else if (p % 3 == 1) {
        ray.origin = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * 2.0f;
      } else {
        const Aabb& box = objects[g() % objects.size()].box;
        ray.origin = box.lower + Vec3(unit(g), unit(g), unit(g)) * (box.upper - box.lower);
      }
      const Vec3 target = c + Vec3(unit(g) - 0.5f, unit(g) * 1.8f - 0.9f, unit(g) - 0.5f);
      ray.direction = p % 4 == 0 ? Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) : target - ray.origin;
      if (ray.direction == Vec3(0.0f)) ray.direction = Vec3(0.0f, -1.0f, 0.0f);
      if (p % 5 == 0) ray.t_max = 0.5f + unit(g);
      packet.set(lane, ray);
    }
    packet.active = static_cast<std::uint8_t>(p % 7 == 0 ? (g() & 0xFFu) : 0xFFu);
    const float* const o[3] = {packet.ox, packet.oy, packet.oz};
    const float* const d[3] = {packet.dx, packet.dy, packet.dz};
    rt::RayBound bound;
    bound.add_lanes(o, d, packet.t_min, packet.t_max, packet.active);
    std::vector<std::uint32_t> tile;
    rt::cull_objects(s, bound, tile);
    const rt::ObjectFilter filter{tile};
    for (const TriangleTest test : kTests) {
      Hit culled[8];
      rt::intersect_packet(s, packet, test, culled, nullptr, &filter);
      const std::uint8_t blocked = rt::occluded_packet(s, packet, test, nullptr, &filter);
      for (int lane = 0; lane < 8; ++lane) {
        if (!(packet.active >> lane & 1u)) continue;
        const Ray ray = packet.ray(lane);
        const Hit single = rt::intersect(s, ray, test);
        ++checked;
        hits += single.valid() ? 1 : 0;
        ASSERT_EQ(culled[lane].triangle_id, single.triangle_id) << "packet " << p << " lane " << lane;
        ASSERT_EQ(culled[lane].instance_id, single.instance_id) << "packet " << p << " lane " << lane;
        if (single.valid()) {
          ASSERT_NEAR(culled[lane].t, single.t, 1e-5f * std::max(1.0f, single.t)) << "packet " << p;
        }
        ASSERT_EQ((blocked >> lane & 1u) != 0, rt::occluded(s, ray, test)) << "packet " << p << " lane " << lane;
      }
    }
  }
  EXPECT_GT(hits, checked / 5);
}

// A large packet's arrays (8 lanes per group) and the view over them.
struct PacketArrays {
  explicit PacketArrays(int groups, float t_max)
      : n(static_cast<std::size_t>(groups) * 8), t0(n, 0.0f), t1(n, t_max),
        active(static_cast<std::size_t>(groups), 0xFFu) {
    for (int a = 0; a < 3; ++a) {
      o[a].resize(n);
      d[a].resize(n);
    }
    rays.groups = groups;
  }
  const rt::LargePacketRays& view() {
    for (int a = 0; a < 3; ++a) {
      rays.o[a] = o[a].data();
      rays.d[a] = d[a].data();
    }
    rays.t_min = t0.data();
    rays.t_max = t1.data();
    rays.active = active.data();
    return rays;
  }
  Ray ray(std::size_t k) const {
    Ray r;
    r.origin = Vec3(o[0][k], o[1][k], o[2][k]);
    r.direction = Vec3(d[0][k], d[1][k], d[2][k]);
    r.t_min = t0[k];
    r.t_max = t1[k];
    return r;
  }
  std::size_t n;
  std::vector<float> o[3], d[3], t0, t1;
  std::vector<std::uint8_t> active;
  rt::LargePacketRays rays;
};

// Random large packets (1 to 64 groups) around the characters: shared
// origins with coherent directions, scattered origins with mixed direction
// signs, origins inside bone boxes, partial lane masks and finite t ranges,
// invalid lanes; given every object or only the tile's cull; lanes clipped to
// each bone leaf's box or not (LargePacketRays::clip_leaf_lanes). Each lane's
// nearest hit and occlusion are the single ray's (the fallback instance
// goes through the 8-ray path, the ground through the small-static tests).
TEST(LargePackets, FindTheSingleRayHits) {
  const rt::Scene& s = scene();
  std::mt19937 g(23);
  const Vec3 c(0.0f, 0.9f, 0.0f);
  const std::span<const rt::TopLevelObject> objects = s.top_level().objects();
  std::vector<std::uint32_t> every(objects.size());
  for (std::uint32_t i = 0; i < every.size(); ++i) every[i] = i;
  std::size_t hits = 0, checked = 0;
  for (int p = 0; p < 240; ++p) {
    const int groups = std::array<int, 5>{1, 3, 8, 32, 64}[static_cast<std::size_t>(p % 5)];
    PacketArrays arrays(groups, kInf);
    const std::size_t n = arrays.n;
    auto& o = arrays.o;
    auto& d = arrays.d;
    auto& t0 = arrays.t0;
    auto& t1 = arrays.t1;
    auto& active = arrays.active;
    const int mode = (p / 4) % 4;
    const Vec3 shared = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * 4.0f;
    const Vec3 aim = c + Vec3(unit(g) - 0.5f, unit(g) * 1.6f - 0.8f, unit(g) - 0.5f);
    const float spread = p % 3 == 0 ? 0.05f : 0.6f;
    for (std::size_t k = 0; k < n; ++k) {
      Vec3 origin;
      if (mode == 0) {
        origin = shared;
      } else if (mode == 1) {
        origin = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * 2.0f;
      } else {
        const Aabb& box = objects[g() % objects.size()].box;
        origin = box.lower + Vec3(unit(g), unit(g), unit(g)) * (box.upper - box.lower);
      }
      const Vec3 target = aim + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * spread;
      Vec3 dir = mode == 3 ? Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) : target - origin;
      if (dir == Vec3(0.0f)) dir = Vec3(0.0f, -1.0f, 0.0f);
      if (p % 5 == 0) t1[k] = 0.5f + unit(g);
      if (k == 5 && p % 6 == 0) dir = Vec3(0.0f);  // invalid: zero direction
      if (k == 9 && p % 6 == 0) origin.x = std::numeric_limits<float>::quiet_NaN();
      for (int a = 0; a < 3; ++a) {
        o[a][k] = origin[a];
        d[a][k] = dir[a];
      }
    }
    for (auto& bits : active) bits = static_cast<std::uint8_t>(p % 7 == 0 ? (g() & 0xFFu) : 0xFFu);
    // Lanes clipped to each bone leaf's box (pixel-sized triangles' packets) or not.
    arrays.rays.clip_leaf_lanes = (p / 2) % 2 == 1;
    const rt::LargePacketRays& rays = arrays.view();
    // The tile's cull, as the renderer does, or every object.
    std::vector<std::uint32_t> tile;
    rt::RayBound bound;
    for (int gr = 0; gr < groups; ++gr) {
      const std::size_t k0 = static_cast<std::size_t>(gr) * 8;
      const float* const op[3] = {&o[0][k0], &o[1][k0], &o[2][k0]};
      const float* const dp[3] = {&d[0][k0], &d[1][k0], &d[2][k0]};
      bound.add_lanes(op, dp, &t0[k0], &t1[k0], active[static_cast<std::size_t>(gr)]);
    }
    rt::cull_objects(s, bound, tile);
    const std::vector<std::uint32_t>& candidates = p % 2 == 0 ? tile : every;
    for (const TriangleTest test : kTests) {
      std::vector<float> ht(n), hu(n), hv(n);
      std::vector<std::uint32_t> htri(n), hinst(n);
      rt::TraversalCounters counters;
      rt::intersect_large_packet(s, rays, test, candidates,
                                 rt::PacketHits{ht.data(), hu.data(), hv.data(), htri.data(), hinst.data()},
                                 &counters);
      std::vector<std::uint8_t> blocked(static_cast<std::size_t>(groups));
      rt::occluded_large_packet(s, rays, test, candidates, blocked.data(), nullptr);
      for (std::size_t k = 0; k < n; ++k) {
        const bool on = (active[k / 8] >> (k % 8) & 1u) != 0;
        const Ray ray = arrays.ray(k);
        const Hit single = on ? rt::intersect(s, ray, test) : Hit{};
        ++checked;
        hits += single.valid() ? 1 : 0;
        ASSERT_EQ(htri[k], single.triangle_id) << "packet " << p << " ray " << k;
        ASSERT_EQ(hinst[k], single.instance_id) << "packet " << p << " ray " << k;
        if (single.valid()) {
          ASSERT_EQ(ht[k], single.t) << "packet " << p << " ray " << k;
        }
        ASSERT_EQ((blocked[k / 8] >> (k % 8) & 1u) != 0, on && rt::occluded(s, ray, test))
            << "packet " << p << " ray " << k;
      }
    }
  }
  EXPECT_GT(hits, checked / 6);
}

// Shadow rays from a point light to surface points (one origin: group
// frusta with far planes, as slabs in the packet's basis or each group's
// own), the light outside, inside a character's bone box and on the ground;
// the occlusion of every ray is the single ray's.
TEST(LargePackets, ShadowRaysToAPointLightMatchSingleRays) {
  const rt::Scene& s = scene();
  std::mt19937 g(5);
  const std::span<const rt::TopLevelObject> objects = s.top_level().objects();
  const Vec3 lights[] = {Vec3(2.0f, 4.0f, 3.0f), objects[objects.size() / 2].box.center(),
                         Vec3(0.3f, 0.0f, 0.8f), Vec3(-0.4f, 1.1f, -0.6f)};
  std::size_t blocked_count = 0, checked = 0;
  for (const Vec3& light : lights) {
    for (int p = 0; p < 60; ++p) {
      const int groups = 1 + static_cast<int>(g() % 64);
      PacketArrays arrays(groups, 1.0f);
      const std::size_t n = arrays.n;
      auto& o = arrays.o;
      auto& d = arrays.d;
      // Points on the characters and the ground, found by rays from a
      // camera-like point through the scene.
      const Vec3 eye(unit(g) * 4.0f - 2.0f, 0.5f + unit(g) * 2.0f, 3.0f);
      const Vec3 aim(unit(g) - 0.5f, unit(g) * 1.8f, unit(g) - 0.5f);
      for (std::size_t k = 0; k < n; ++k) {
        Ray ray;
        ray.origin = eye;
        ray.direction = aim + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * 0.4f - eye;
        const Hit hit = rt::intersect(s, ray, TriangleTest::kFast);
        const Vec3 at = hit.valid() ? ray.at(hit.t * 0.9999f) : Vec3(unit(g), 0.001f, unit(g));
        for (int a = 0; a < 3; ++a) {
          o[a][k] = light[a];
          d[a][k] = at[a] - light[a];
        }
      }
      rt::LargePacketRays rays = arrays.view();
      std::vector<std::uint32_t> every(objects.size());
      for (std::uint32_t i = 0; i < every.size(); ++i) every[i] = i;
      for (const TriangleTest test : kTests) {
        // The groups' slabs, or their own frusta (LargePacketRays::group_frusta),
        // with and without lanes clipped to each bone leaf's box.
        rays.group_frusta = p % 2 == 1;
        rays.clip_leaf_lanes = (p / 2) % 2 == 1;
        std::vector<std::uint8_t> blocked(static_cast<std::size_t>(groups));
        rt::occluded_large_packet(s, rays, test, every, blocked.data(), nullptr);
        for (std::size_t k = 0; k < n; ++k) {
          const bool single = rt::occluded(s, arrays.ray(k), test);
          ++checked;
          blocked_count += single ? 1 : 0;
          ASSERT_EQ((blocked[k / 8] >> (k % 8) & 1u) != 0, single) << "ray " << k;
        }
      }
    }
  }
  EXPECT_GT(blocked_count, checked / 20);
  EXPECT_LT(blocked_count, checked - checked / 20);
}

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
  rt::intersect_static_tile(tile, camera.eye(), s, counters);
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

// A checkered floor of 24 x 24 quads with a box on it (one static mesh of
// 1,164 triangles, as the demo's arena): a tile that sees a few quads
// gathers them from the mesh's tree and finds every single-ray hit and
// occlusion; a tile that sees the whole floor does not qualify.
// A tile's cone (static_tiles.h TileCone) never drops a triangle that a
// ray inside it hits, by either triangle test: random cones of four or
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
  rt::intersect_static_tile(tile, camera.eye(), s, counters);
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
    rt::intersect_static_tile(tile, camera.eye(), s, counters);
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
        rt::reconstruct_surfaces(sc, Vec3(0.7f), s);
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

// aim_shadow_rays bounds where the rays of offset_shadow_rays end without
// computing them: every end (a directional light's ray origin; for a point
// light the rounded direction from the light, which the bound's corner
// directions must hold) lies inside s.shadow_ends, at coordinates from
// 1e-3 to 1e6, with surfaces at zero too. The bound stays on the lit side
// of a flat receiver, so a ground in the open is culled.
// Blocks whose lanes hit several triangles: the same triangle index on
// both characters and on the ground, lanes that miss between them, in every
// order. Each block's corners are loaded once per distinct (instance,
// triangle) and blended into its lanes (render/stages/tile_stages.cpp
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
    rt::reconstruct_surfaces(sc, Vec3(0.7f), s);
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

struct Frame {
  std::vector<std::uint8_t> color;
  std::vector<float> depth;
  std::vector<Vec3> normal;
  std::vector<std::uint32_t> triangle, instance;
};

Frame render(const rt::Scene& sc, const rt::PinholeCamera& camera, int tile, int packet_rays, TriangleTest test,
             JobSystem& jobs) {
  const std::size_t n = static_cast<std::size_t>(camera.width() * camera.height());
  Frame f;
  f.color.resize(4 * n);
  f.depth.resize(n);
  f.normal.resize(n);
  f.triangle.resize(n);
  f.instance.resize(n);
  rt::FrameBuffers buffers{camera.width(), camera.height(), f.color, {}, f.depth, f.normal, f.triangle, f.instance, {}};
  rt::RenderSettings settings;
  settings.tile_size = tile;
  settings.packet_rays = packet_rays;
  settings.triangle_test = test;
  rt::Renderer renderer;
  EXPECT_TRUE(renderer.render(sc, camera, settings, buffers, jobs).ok());
  return f;
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

// One idle mannequin, nothing else.
std::unique_ptr<rt::Scene> one_mannequin() {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene->add_instance(character).value();
  EXPECT_TRUE(scene->set_bones(instance, testing_support::clip_pose(m.model, "idle", 0.3, Affine3::identity())).ok());
  JobSystem jobs(2);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return scene;
}

// By hand: a camera on the axis through the box's centre, looking along -z,
// sees the box's near face widest, dx / z_near by dy / z_near in slope, at
// H / (2 tan(fovy / 2)) pixels per unit of slope on a square image. Image
// sizes put that at 1.6 and 2.5 pixels per triangle, either side of
// kFineBoxPixelsPerTriangle (2).
TEST(Renderer, CharactersLookFineWhereTheirProjectedBoxesHoldAboutAPixelPerTriangle) {
  const std::unique_ptr<rt::Scene> sc = one_mannequin();
  Aabb box = Aabb::empty();
  for (const Aabb& b : sc->instances()[0].bone_world_boxes) box.extend(b);
  ASSERT_TRUE(box.lower.x < box.upper.x);
  const double triangles = static_cast<double>(sc->characters()[0].mesh->triangles.size());
  const Vec3 centre = box.center();
  const double dx = box.upper.x - box.lower.x, dy = box.upper.y - box.lower.y, dz = box.upper.z - box.lower.z;
  const double distance = 6.0;  // eye to the box's centre
  const double z_near = distance - 0.5 * dz;
  const double fovy = 30.0, tan_half = std::tan(fovy * 0.5 * std::acos(-1.0) / 180.0);
  const Vec3 eye = centre + Vec3(0.0f, 0.0f, static_cast<float>(distance));
  for (const double per_triangle : {1.6, 2.5}) {
    // pixels = (dx / z_near) (dy / z_near) (H / (2 tan))^2 = per_triangle * triangles.
    const int size = static_cast<int>(
        std::lround(2.0 * tan_half * z_near * std::sqrt(per_triangle * triangles / (dx * dy))));
    const double s = size / (2.0 * tan_half);
    const double expected = (dx / z_near) * (dy / z_near) * s * s / triangles;
    ASSERT_NEAR(expected, per_triangle, 0.1) << size;
    const auto camera = rt::PinholeCamera::create({eye, centre, Vec3(0, 1, 0), static_cast<float>(fovy)}, size, size);
    ASSERT_TRUE(camera.ok());
    EXPECT_EQ(rt::characters_look_fine(*sc, *camera), expected <= rt::kFineBoxPixelsPerTriangle)
        << size << " px: " << expected << " pixels per triangle";
  }
  // An eye inside the box: coarse, however small the image.
  const auto inside = rt::PinholeCamera::create({centre, centre - Vec3(0, 0, 1), Vec3(0, 1, 0), 30.0f}, 1, 1);
  ASSERT_TRUE(inside.ok());
  EXPECT_FALSE(rt::characters_look_fine(*sc, *inside));
  // No character at all.
  const rt::Scene empty;
  const auto far = rt::PinholeCamera::create({eye, centre, Vec3(0, 1, 0), 30.0f}, 1, 1);
  ASSERT_TRUE(far.ok());
  EXPECT_FALSE(rt::characters_look_fine(empty, *far));
  EXPECT_TRUE(rt::characters_look_fine(*sc, *far));
}

// Far from the camera the mannequins' triangles are a pixel or less: the
// regions split, and the image is the single rays' either way.
TEST(Renderer, SplitShadowPacketsOnFineTrianglesShadeAsSingleRays) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 14.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 8.0f}, 67, 61)
          .value();
  const std::size_t n = static_cast<std::size_t>(camera.width() * camera.height());
  const auto color = [&](int packet_rays, bool split, rt::TraversalCounters* shadow) {
    std::vector<std::uint8_t> rgba(4 * n);
    rt::FrameBuffers buffers{camera.width(), camera.height(), rgba, {}, {}, {}, {}, {}, {}};
    rt::RenderSettings settings;
    settings.packet_rays = packet_rays;
    settings.split_fine_shadow_packets = split;
    rt::Renderer renderer;
    const Expected<rt::RenderStats> stats = renderer.render(sc, camera, settings, buffers, jobs);
    EXPECT_TRUE(stats.ok());
    if (shadow != nullptr && stats.ok()) *shadow = stats->shadow;
    return rgba;
  };
  const std::vector<std::uint8_t> single = color(1, true, nullptr);
  for (const int packet_rays : {256, 512}) {
    rt::TraversalCounters whole, split;
    EXPECT_EQ(color(packet_rays, false, &whole), single) << packet_rays;
    EXPECT_EQ(color(packet_rays, true, &split), single) << packet_rays;
    // Smaller packets walk the trees otherwise: the split happened.
    EXPECT_TRUE(split.node_visits != whole.node_visits || split.triangle_tests != whole.triangle_tests)
        << packet_rays;
  }
}

// Odd image sizes and tile sizes put partial 4x2 blocks on every tile and
// image edge; cameras inside a character and inside a bone box start rays
// inside objects. Every pixel is checked against the single-ray query and
// against brute force, and packets against single rays for the whole image.
TEST(Renderer, PacketsMatchSingleRaysAndBruteForceAtEdgesAndInsideCharacters) {
  const rt::Scene& sc = scene();
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  JobSystem jobs(2);
  const Aabb chest = sc.top_level().objects()[sc.top_level().objects().size() / 3].box;
  const rt::CameraDesc cameras[] = {
      {Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f},   // outside
      {Vec3(-0.45f, 1.2f, 0.02f), Vec3(0.5f, 0.8f, -1.0f), Vec3(0, 1, 0), 100.0f},  // inside a mannequin
      {chest.center(), chest.center() + Vec3(0.3f, -0.2f, 1.0f), Vec3(0, 1, 0), 120.0f},  // inside a bone box
  };
  const std::pair<int, int> sizes[] = {{37, 23}, {29, 31}};
  std::size_t checked = 0, character = 0;
  for (const rt::CameraDesc& desc : cameras) {
    for (const auto& [w, h] : sizes) {
      const auto camera = rt::PinholeCamera::create(desc, w, h).value();
      for (const TriangleTest test : kTests) {
        const Frame single = render(sc, camera, 16, 1, test, jobs);
        for (const int packet_rays : {8, 64, 256, 512}) {
          for (const int tile : {1, 3, 5, 16, 64}) {
            const Frame packets = render(sc, camera, tile, packet_rays, test, jobs);
            EXPECT_EQ(packets.triangle, single.triangle) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.instance, single.instance) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.depth, single.depth) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.color, single.color) << "tile " << tile << ", " << packet_rays << " rays";
          }
        }
        for (int y = 0; y < h; ++y) {
          for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y * w + x);
            const Ray ray = camera.ray(x, y);
            const Hit ours{single.depth[i] / glm::length(ray.direction), 0.0f, 0.0f, single.triangle[i],
                           single.instance[i]};
            const Hit ref = testing_support::nearest(soup, ray, test);
            ++checked;
            character += ref.valid() && ref.instance_id < 2 ? 1 : 0;
            ASSERT_EQ(single.triangle[i], rt::intersect(sc, ray, test).triangle_id) << x << "," << y;
            ASSERT_TRUE(testing_support::same_nearest(rt::intersect(sc, ray, test), ref, soup, ray, test))
                << x << "," << y << " tri " << ours.triangle_id << " ref " << ref.triangle_id;
          }
        }
      }
    }
  }
  EXPECT_GT(character, checked / 10);
}

// Bytes per pixel of each output, in FrameBuffers order: RGBA8, RGBA32F,
// depth, normal, triangle id, instance id.
constexpr std::size_t kOutputPixelBytes[] = {4, 16, 4, sizeof(Vec3), 4, 4};

// One host plane: `rows` rows `pitch` bytes apart, starting `offset` bytes
// into line-aligned storage filled with a sentinel byte (and a little more,
// so that the span's whole elements reach the last row's end).
struct HostPlane {
  LineAlignedVector<std::byte> bytes;
  std::size_t offset = 0, pitch = 0;
  HostPlane(std::size_t offset_bytes, std::size_t pitch_bytes, int rows)
      : bytes(offset_bytes + pitch_bytes * static_cast<std::size_t>(rows) + 16, std::byte{0xA5}),
        offset(offset_bytes),
        pitch(pitch_bytes) {}
  template <class T>
  std::span<T> span() {
    return {reinterpret_cast<T*>(bytes.data() + offset), (bytes.size() - offset) / sizeof(T)};
  }
};

// Every output, laid out with each row `row_bytes(output)` rounded up to a
// multiple of `align` plus `pad` bytes, starting `offset` bytes past a line.
struct HostFrame {
  std::vector<HostPlane> planes;
  rt::FrameBuffers buffers;
  HostFrame(int w, int h, std::size_t align, std::size_t pad, std::size_t offset) {
    for (const std::size_t bytes_per_pixel : kOutputPixelBytes) {
      const std::size_t row = bytes_per_pixel * static_cast<std::size_t>(w);
      planes.emplace_back(offset, (row + align - 1) / align * align + pad, h);
    }
    buffers.width = w;
    buffers.height = h;
    buffers.color_rgba8 = planes[0].span<std::uint8_t>();
    buffers.color_rgba32f = planes[1].span<float>();
    buffers.depth = planes[2].span<float>();
    buffers.normal = planes[3].span<Vec3>();
    buffers.triangle_id = planes[4].span<std::uint32_t>();
    buffers.instance_id = planes[5].span<std::uint32_t>();
    buffers.row_pitch = {planes[0].pitch, planes[1].pitch, planes[2].pitch,
                         planes[3].pitch, planes[4].pitch, planes[5].pitch};
  }
  // Plane p's row y: its pixels, and the padding after them.
  std::span<const std::byte> row(std::size_t p, int y, std::size_t row_bytes) const {
    return {planes[p].bytes.data() + planes[p].offset + static_cast<std::size_t>(y) * planes[p].pitch, row_bytes};
  }
  std::span<const std::byte> padding(std::size_t p, int y, std::size_t row_bytes) const {
    return {planes[p].bytes.data() + planes[p].offset + static_cast<std::size_t>(y) * planes[p].pitch + row_bytes,
            planes[p].pitch - row_bytes};
  }
};

// Rows that start on a line are staged and stored by streaming whole lines
// (render/output/output_staging.h); the others are written in place. Both must
// give every output the same bytes, and neither may touch the padding
// between rows, whatever the tile and image edges do to the lines.
TEST(Renderer, StagedAndInPlaceOutputsHoldTheSameBytes) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const rt::CameraDesc desc{Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f};
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 40}}) {
    const auto camera = rt::PinholeCamera::create(desc, w, h).value();
    for (const int tile : {5, 16, 32}) {
      rt::RenderSettings settings;
      settings.tile_size = tile;
      // In place: rows 4 bytes past a line. Staged: rows on lines, packed
      // where the row is whole lines, else padded to them, or padded further.
      HostFrame in_place(w, h, 4, 0, 4);
      HostFrame staged(w, h, 64, 0, 0);
      HostFrame staged_padded(w, h, 64, 128, 0);
      rt::Renderer renderer;
      ASSERT_TRUE(renderer.render(sc, camera, settings, in_place.buffers, jobs).ok());
      ASSERT_TRUE(renderer.render(sc, camera, settings, staged.buffers, jobs).ok());
      ASSERT_TRUE(renderer.render(sc, camera, settings, staged_padded.buffers, jobs).ok());
      for (std::size_t p = 0; p < 6; ++p) {
        const std::size_t row_bytes = kOutputPixelBytes[p] * static_cast<std::size_t>(w);
        for (int y = 0; y < h; ++y) {
          const auto reference = in_place.row(p, y, row_bytes);
          for (const HostFrame* frame : {&staged, &staged_padded}) {
            const auto row = frame->row(p, y, row_bytes);
            ASSERT_TRUE(std::equal(row.begin(), row.end(), reference.begin()))
                << "plane " << p << " row " << y << " tile " << tile << " " << w << "x" << h;
            for (const std::byte b : frame->padding(p, y, row_bytes)) ASSERT_EQ(b, std::byte{0xA5}) << "plane " << p;
          }
          for (const std::byte b : in_place.padding(p, y, row_bytes)) ASSERT_EQ(b, std::byte{0xA5}) << "plane " << p;
        }
      }
      // The reference is the packed render of the test above, pixel for
      // pixel, and sees the characters.
      const Frame packed = render(sc, camera, tile, 64, TriangleTest::kFast, jobs);
      EXPECT_GT(std::count_if(packed.instance.begin(), packed.instance.end(),
                              [](std::uint32_t id) { return id < 2; }),
                w * h / 20);
      for (int y = 0; y < h; ++y) {
        const auto row = in_place.row(4, y, 4 * static_cast<std::size_t>(w));
        ASSERT_TRUE(std::equal(row.begin(), row.end(),
                               reinterpret_cast<const std::byte*>(packed.triangle.data() + y * w)))
            << "row " << y;
      }
    }
  }
}

// Colour alone (a game's frame) takes its own path through the shading
// (shade_rgba8_only, render/stages/tile_stages.cpp); its bytes must be those of a
// render that asks for every output, staged or in place, with partial
// blocks at the image's edges and lights of both kinds.
TEST(Renderer, ColourAloneHoldsTheBytesOfARenderOfEveryOutput) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const rt::CameraDesc desc{Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f};
  rt::Light lights[2];
  lights[0].position = Vec3(-2.0f, 5.0f, 3.0f);
  lights[0].color = Vec3(0.9f, 0.6f, 0.3f);
  lights[1].kind = rt::Light::Kind::kDirectional;
  lights[1].direction = Vec3(0.5f, 1.0f, -0.2f);
  lights[1].color = Vec3(0.2f, 0.3f, 0.5f);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 40}}) {
    const auto camera = rt::PinholeCamera::create(desc, w, h).value();
    const std::size_t row_bytes = 4 * static_cast<std::size_t>(w);
    for (const std::size_t light_count : {std::size_t{1}, std::size_t{2}}) {
      for (const int tile : {5, 16, 32}) {
        rt::RenderSettings settings;
        settings.tile_size = tile;
        settings.lights = std::span<const rt::Light>(lights, light_count);
        HostFrame every(w, h, 64, 0, 0);
        rt::Renderer renderer;
        ASSERT_TRUE(renderer.render(sc, camera, settings, every.buffers, jobs).ok());
        std::size_t on_character = 0;
        for (int y = 0; y < h; ++y) {
          const auto ids = every.row(5, y, row_bytes);
          for (int x = 0; x < w; ++x) {
            std::uint32_t id;
            std::memcpy(&id, ids.data() + 4 * x, 4);
            on_character += id < 2 ? 1 : 0;
          }
        }
        EXPECT_GT(on_character, static_cast<std::size_t>(w * h / 20));
        // Staged (rows on lines) and in place (rows 4 bytes past a line).
        for (const auto& [align, offset] : {std::pair<std::size_t, std::size_t>{64, 0}, {4, 4}}) {
          HostPlane color(offset, (row_bytes + align - 1) / align * align, h);
          rt::FrameBuffers only;
          only.width = w;
          only.height = h;
          only.color_rgba8 = color.span<std::uint8_t>();
          only.row_pitch.color_rgba8 = color.pitch;
          ASSERT_TRUE(renderer.render(sc, camera, settings, only, jobs).ok());
          for (int y = 0; y < h; ++y) {
            const auto reference = every.row(0, y, row_bytes);
            const std::byte* row = color.bytes.data() + offset + static_cast<std::size_t>(y) * color.pitch;
            ASSERT_TRUE(std::equal(reference.begin(), reference.end(), row))
                << "row " << y << " tile " << tile << " " << w << "x" << h << ", " << light_count << " lights";
            for (std::size_t i = row_bytes; i < color.pitch; ++i) ASSERT_EQ(row[i], std::byte{0xA5});
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace sinew
