// Lazy skinning for batches of queries (FrameOptions::rays): a 16 x 16 grid
// of mannequins, poses advancing each tick, some outside the pose space;
// random hit scans (short segments), long rays and rays from inside the
// grid. The nearest hits and occlusion equal brute force over every posed
// triangle with lazy skinning on and off, and a batch of short segments
// skins only the instances they reach. RayReach alone never misses a box a
// segment enters.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "raytrace/scene/ray_reach.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

constexpr int kColumns = 16;
constexpr int kInstances = kColumns * kColumns;

float uniform(std::mt19937& g, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(g() >> 8) * 0x1.0p-24f;
}

Vec3 random_unit(std::mt19937& g) {
  for (;;) {
    const Vec3 v(uniform(g, -1, 1), uniform(g, -1, 1), uniform(g, -1, 1));
    const float length = glm::length(v);
    if (length > 0.1f && length <= 1.0f) return v / length;
  }
}

// Hit scans: short segments between the characters; long rays across the
// grid; some from inside a character's box.
std::vector<Ray> random_rays(std::mt19937& g, bool short_segments) {
  std::vector<Ray> rays;
  const float extent = 0.6f * kColumns;
  for (int i = 0; i < (short_segments ? 40 : 150); ++i) {
    Ray ray;
    ray.origin = Vec3(uniform(g, -extent, extent), uniform(g, 0.1f, 2.0f), uniform(g, -2.4f * extent, 0.5f));
    ray.direction = random_unit(g);
    if (short_segments) {
      ray.t_max = uniform(g, 0.2f, 2.5f);
    } else if (i % 3 == 0) {
      ray.origin = Vec3(uniform(g, -extent, extent), uniform(g, 0.5f, 5.0f), 4.0f);
      ray.direction = glm::normalize(Vec3(uniform(g, -0.5f, 0.5f), uniform(g, -0.3f, 0.05f), -1.0f));
    }
    rays.push_back(ray);
  }
  return rays;
}

TEST(LazyQuerySkinning, AnswersEqualBruteForceWithLazySkinningOnAndOff) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  std::vector<std::uint32_t> ids;
  for (int i = 0; i < kInstances; ++i) ids.push_back(scene.add_instance(character).value());
  rt::StaticMeshDesc ground;
  ground.positions = {{-40, 0, -40}, {40, 0, -40}, {-40, 0, 40}, {40, 0, 40}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  ASSERT_TRUE(scene.add_static_mesh(ground).ok());
  JobSystem jobs(2);
  std::mt19937 g(2053);
  for (int tick = 0; tick < 3; ++tick) {
    for (int i = 0; i < kInstances; ++i) {
      const float x = 1.2f * static_cast<float>(i % kColumns - kColumns / 2);
      const float z = -1.2f * static_cast<float>(i / kColumns);
      const double t = 0.1 * tick + 0.37 * i;
      ASSERT_TRUE(scene
                      .set_bones(ids[static_cast<std::size_t>(i)],
                                 testing_support::clip_pose(m.model, i % 5 == 0 ? "kick" : "idle",
                                                            i % 5 == 0 ? std::fmod(t, 0.8) : t,
                                                            Affine3::translation(Vec3(x, 0, z))))
                      .ok());
    }
    for (const bool short_segments : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "tick " << tick << " short " << short_segments);
      const std::vector<Ray> rays = random_rays(g, short_segments);
      // Lazy off: every instance; the brute force reads its positions.
      rt::FrameOptions full;
      full.normals = false;
      const rt::FrameStats all = scene.prepare_frame(full, jobs).value();
      EXPECT_EQ(all.skinned_instances, static_cast<std::uint32_t>(kInstances));
      const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(scene);
      std::vector<Hit> full_hits;
      std::vector<bool> full_blocked;
      for (const Ray& ray : rays) {
        full_hits.push_back(rt::intersect(scene, ray, rt::TriangleTest::kFast));
        full_blocked.push_back(rt::occluded(scene, ray, rt::TriangleTest::kFast));
      }
      // Lazy on.
      rt::FrameOptions lazy = full;
      lazy.rays = rays;
      const rt::FrameStats some = scene.prepare_frame(lazy, jobs).value();
      EXPECT_EQ(some.skinned_instances + some.culled_instances, static_cast<std::uint32_t>(kInstances));
      if (short_segments) {
        EXPECT_LT(some.skinned_instances, static_cast<std::uint32_t>(kInstances / 2));
      }
      int hits = 0;
      for (std::size_t r = 0; r < rays.size(); ++r) {
        const Hit ref = testing_support::nearest(soup, rays[r], rt::TriangleTest::kFast);
        const bool blocked = testing_support::any_hit(soup, rays[r], rt::TriangleTest::kFast);
        const Hit lazy_hit = rt::intersect(scene, rays[r], rt::TriangleTest::kFast);
        EXPECT_TRUE(testing_support::same_nearest(full_hits[r], ref, soup, rays[r], rt::TriangleTest::kFast)) << r;
        EXPECT_TRUE(testing_support::same_nearest(lazy_hit, ref, soup, rays[r], rt::TriangleTest::kFast)) << r;
        EXPECT_EQ(full_blocked[r], blocked) << r;
        EXPECT_EQ(rt::occluded(scene, rays[r], rt::TriangleTest::kFast), blocked) << r;
        hits += ref.valid() && ref.instance_id < static_cast<std::uint32_t>(kInstances) ? 1 : 0;
      }
      if (!short_segments) {
        EXPECT_GT(hits, 5);  // the rays do hit characters
      }
    }
  }
}

TEST(RayReach, NeverMissesABoxASegmentEnters) {
  std::mt19937 g(11);
  rt::RayReach reach;
  std::vector<std::uint8_t> reached;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Aabb> boxes;
    for (int i = 0; i < 300; ++i) {
      const Vec3 c(uniform(g, -50, 50), uniform(g, -5, 5), uniform(g, -50, 50));
      const Vec3 h(uniform(g, 0.0f, 1.0f), uniform(g, 0.0f, 2.0f), uniform(g, 0.0f, 1.0f));
      boxes.push_back(i % 50 == 7 ? Aabb::empty() : Aabb{c - h, c + h});
    }
    std::vector<Ray> rays;
    std::vector<std::size_t> targets;
    for (int r = 0; r < 200; ++r) {
      // Aimed at a point inside a random box, ending just past it or not.
      const std::size_t target = g() % boxes.size();
      if (boxes[target].is_empty()) continue;
      const Vec3 p = boxes[target].lower + Vec3(uniform(g, 0, 1), uniform(g, 0, 1), uniform(g, 0, 1)) *
                                               (boxes[target].upper - boxes[target].lower);
      Ray ray;
      ray.origin = p - uniform(g, 0.0f, 80.0f) * random_unit(g);
      ray.direction = p - ray.origin;
      if (r % 7 == 0) ray.direction.y = 0.0f;  // flat rays
      ray.t_max = r % 2 ? 1.0f + 1e-3f : std::numeric_limits<float>::infinity();
      if (r % 7 == 0) ray.origin.y = p.y;
      rays.push_back(ray);
      targets.push_back(target);
    }
    ASSERT_TRUE(reach.mark(rays, boxes, 1e-4, reached).ok());
    for (std::size_t r = 0; r < rays.size(); ++r) EXPECT_TRUE(reached[targets[r]]) << trial << " " << r;
    std::size_t count = 0;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (boxes[i].is_empty()) {
        EXPECT_FALSE(reached[i]);
      }
      count += reached[i];
    }
    EXPECT_LT(count, boxes.size());  // not everything
  }
}

}  // namespace
}  // namespace sinew
