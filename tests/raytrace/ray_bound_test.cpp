// RayBound (cull/ray_bound.h), the bound over a set of rays that culls
// boxes: it never culls a box some ray of the set enters (against a
// double-precision slab test), culls a wide flat box by its height and not
// its width, culls nothing for non-finite rays, bounds groups with one
// shared origin as their lanes, culls what lies beyond short segments of
// mixed directions, and through cull_objects keeps every object a ray
// enters in scenes of few and many objects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "raytrace/accel/top_level.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/jobs/job_system.h"
#include "tests/raytrace/render_test_support.h"
#include "tests/support/idle_mannequin.h"
#include "tests/support/slab_test.h"

namespace sinew {
namespace {

using testing_support::kInf;
using testing_support::unit;

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
    const rt::IntervalBound test = bound.test();
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

// Segments whose directions take both signs on every axis (ambient
// occlusion rays about a normal, an area light's samples): the slabs bound
// no axis, the box the segments sweep does. Short rays cull the boxes
// beyond their length; samples from a light that all end just above a
// floor cull the floor, though their ranges of origin and direction reach
// it; and a box they pass through is kept.
TEST(RayBound, SegmentsOfMixedDirectionsCullWhatLiesBeyondThem) {
  std::mt19937 g(11);
  alignas(32) float o[3][8], d[3][8], t0[8], t1[8];
  const float* const op[3] = {o[0], o[1], o[2]};
  const float* const dp[3] = {d[0], d[1], d[2]};
  // Ambient occlusion: from near the origin, 0.5 long, every direction.
  rt::RayBound ao;
  for (int group = 0; group < 4; ++group) {
    for (int lane = 0; lane < 8; ++lane) {
      for (int a = 0; a < 3; ++a) {
        o[a][lane] = 0.2f * (unit(g) - 0.5f);
        d[a][lane] = unit(g) - 0.5f;
      }
      t0[lane] = 0.0f;
      t1[lane] = 1.0f;
    }
    ao.add_lanes(op, dp, t0, t1, 0xFFu);
  }
  const rt::IntervalBound near = ao.test();
  for (int a = 0; a < 3; ++a) {
    for (const float side : {-1.0f, 1.0f}) {
      Vec3 c(0.0f);
      c[a] = side * 1.0f;
      EXPECT_FALSE(near.may_enter({c - Vec3(0.2f), c + Vec3(0.2f)}, 1e-6f)) << "axis " << a << " side " << side;
    }
  }
  EXPECT_TRUE(near.may_enter({Vec3(0.3f, -0.05f, -0.05f), Vec3(0.4f, 0.05f, 0.05f)}, 1e-6f));
  // Samples from a sphere light around (0, 3, 0) to points 1e-3 above a
  // floor at y = 0.
  rt::RayBound light;
  for (int group = 0; group < 4; ++group) {
    for (int lane = 0; lane < 8; ++lane) {
      const Vec3 from(0.5f * (unit(g) - 0.5f), 3.0f + 0.5f * (unit(g) - 0.5f), 0.5f * (unit(g) - 0.5f));
      const Vec3 end(4.0f * (unit(g) - 0.5f), 1e-3f, 4.0f * (unit(g) - 0.5f));
      for (int a = 0; a < 3; ++a) {
        o[a][lane] = from[a];
        d[a][lane] = end[a] - from[a];
      }
    }
    light.add_lanes(op, dp, t0, t1, 0xFFu);
  }
  const rt::IntervalBound samples = light.test();
  EXPECT_FALSE(samples.may_enter({Vec3(-100.0f, 0.0f, -100.0f), Vec3(100.0f, 0.0f, 100.0f)}, 1e-5f));
  EXPECT_TRUE(samples.may_enter({Vec3(-100.0f, 0.0f, -100.0f), Vec3(100.0f, 2e-3f, 100.0f)}, 1e-5f));
  // Without the ends' box (the ranges of o and d alone), the floor is reached.
  rt::RayRanges ranges;
  for (int a = 0; a < 3; ++a) {
    ranges.o_lo[a] = a == 1 ? 2.75f : -0.25f;
    ranges.o_hi[a] = a == 1 ? 3.25f : 0.25f;
    ranges.d_lo[a] = a == 1 ? -3.25f : -2.25f;
    ranges.d_hi[a] = a == 1 ? -2.75f : 2.25f;
  }
  ranges.t_lo = 0.0f;
  ranges.t_hi = 1.0f;
  EXPECT_TRUE(rt::IntervalBound(ranges).may_enter({Vec3(-100.0f, 0.0f, -100.0f), Vec3(100.0f, 0.0f, 100.0f)}, 1e-5f));
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
    const rt::IntervalBound a = mixed.test(), b = by_lane.test();
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
    const rt::IntervalBound a = grouped.test(), b = one_by_one.test(), c = run.test(), e = run_by_lane.test();
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

}  // namespace
}  // namespace sinew
