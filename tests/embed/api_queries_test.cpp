// World's ray queries and instance removal (include/sinew/world.h) against
// an independent reference: every posed triangle of the same instances in a
// flat list, intersected one by one (tests/support/brute_force.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tests/embed/api_test_support.h"
#include "tests/support/brute_force.h"

namespace sinew {
namespace {

using testing_support::Frame;
using testing_support::load_mannequin;
using testing_support::mannequin_pack_path;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kW = 64;
constexpr int kH = 56;

const api::Float3 kQuad[] = {{-3, 0, -3}, {3, 0, -3}, {-3, 0, 3}, {3, 0, 3}};
const std::uint32_t kQuadIndices[] = {0, 2, 1, 1, 2, 3};

// Two mannequins (one walking, which the idle-baked pack does not cover:
// its escaped triangles go through the fallback) and a ground, in the API
// and, posed alike, as the reference's triangle soup (ids in the same
// order: instance 0, ground 1, instance 2).
struct Scenes {
  api::World world = api::World::create().value();
  api::InstanceId walker = 0, ground = 0, kicker = 0;
  std::vector<testing_support::SoupTriangle> soup;

  Scenes() {
    const api::Character character = load_mannequin();
    walker = world.add_instance(character).value();
    ground = world.add_static_mesh({kQuad, kQuadIndices, {0.5f, 0.5f, 0.5f}}).value();
    api::InstanceDesc moved;
    moved.transform = api::Matrix3x4::translation(0.8f, 0.0f, -0.3f);
    kicker = world.add_instance(character, moved).value();
    EXPECT_TRUE(world.pose_at(walker, "walk", 0.4).ok());
    EXPECT_TRUE(world.pose_at(kicker, "kick", 0.55).ok());
    soup = reference({{"walk", 0.4, Affine3::identity()}, {"kick", 0.55, translation(0.8f, 0.0f, -0.3f)}});
  }

  struct Pose {
    const char* clip;
    double t;
    Affine3 placement;
  };
  static Affine3 translation(float x, float y, float z) {
    Affine3 a = Affine3::identity();
    a.rows[0].w = x;
    a.rows[1].w = y;
    a.rows[2].w = z;
    return a;
  }
  // The posed triangles of instances at `poses` with the ground between the
  // first and the second, as World numbers them.
  static std::vector<testing_support::SoupTriangle> reference(const std::vector<Pose>& poses) {
    const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
    rt::Scene scene;
    const std::uint32_t character = scene.add_character(pack.model().mesh, pack.fuzzy()).value();
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (i == 1) {
        rt::StaticMeshDesc ground;
        for (const api::Float3& p : kQuad) ground.positions.push_back(Vec3(p.x, p.y, p.z));
        ground.triangles = {{0, 2, 1}, {1, 2, 3}};
        EXPECT_TRUE(scene.add_static_mesh(std::move(ground)).ok());
      }
      const std::uint32_t id = scene.add_instance(character).value();
      EXPECT_TRUE(scene
                      .set_bones(id, testing_support::clip_pose(pack.model(), poses[i].clip, poses[i].t,
                                                                poses[i].placement))
                      .ok());
    }
    JobSystem jobs(1);
    EXPECT_TRUE(scene.prepare_frame({}, jobs).ok());
    return testing_support::world_triangles(scene);
  }
};

sinew::Ray to_internal(const api::Ray& r) {
  sinew::Ray ray;
  ray.origin = Vec3(r.origin.x, r.origin.y, r.origin.z);
  ray.direction = Vec3(r.direction.x, r.direction.y, r.direction.z);
  ray.t_min = r.t_min;
  ray.t_max = r.t_max;
  return ray;
}

rt::TriangleTest to_internal(api::TriangleTest test) {
  return test == api::TriangleTest::kWatertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast;
}

// Camera rays through a grid of pixels (picking), rays between random
// points around the characters, some of them segments, and rays from
// inside a character's box.
std::vector<api::Ray> query_rays() {
  std::vector<api::Ray> rays;
  const auto camera = rt::PinholeCamera::create(testing_support::test_camera_internal(), kW, kH).value();
  for (int y = 0; y < kH; y += 2) {
    for (int x = 0; x < kW; x += 2) {
      const sinew::Ray r = camera.ray(x, y);
      rays.push_back({{r.origin.x, r.origin.y, r.origin.z}, {r.direction.x, r.direction.y, r.direction.z}});
    }
  }
  std::mt19937 g(17);
  std::uniform_real_distribution<float> around(-1.2f, 1.2f), height(0.05f, 1.9f), unit(-1.0f, 1.0f);
  for (int i = 0; i < 1500; ++i) {
    api::Ray r;
    r.origin = {around(g), height(g), around(g)};
    r.direction = {unit(g), unit(g), unit(g)};
    if (r.direction.x == 0.0f && r.direction.y == 0.0f && r.direction.z == 0.0f) continue;
    if (i % 3 == 1) r.t_max = 0.5f + 0.5f * std::fabs(unit(g));  // a segment
    if (i % 5 == 2) r.t_min = 0.1f;                             // starting a little way out
    rays.push_back(r);
  }
  return rays;
}

TEST(ApiQueries, NearestHitsMatchBruteForceOverThePosedTriangles) {
  Scenes s;
  const std::vector<api::Ray> rays = query_rays();
  for (const api::TriangleTest test : {api::TriangleTest::kFast, api::TriangleTest::kWatertight}) {
    std::vector<api::RayHit> batch(rays.size());
    const api::Status status = s.world.intersect(rays, batch, test);
    ASSERT_TRUE(status.ok()) << status.error().message;
    std::size_t on[3] = {0, 0, 0};
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const sinew::Ray ray = to_internal(rays[i]);
      const Hit ref = testing_support::nearest(s.soup, ray, to_internal(test));
      const auto single = s.world.intersect(rays[i], test);
      ASSERT_TRUE(single.ok()) << single.error().message;
      for (const api::RayHit& h : {*single, batch[i]}) {
        const Hit ours{h.t, h.u, h.v, h.triangle, h.instance};
        ASSERT_TRUE(testing_support::same_nearest(ours, ref, s.soup, ray, to_internal(test)))
            << "ray " << i << ": instance " << h.instance << " triangle " << h.triangle << " t " << h.t
            << ", brute force: instance " << ref.instance_id << " triangle " << ref.triangle_id << " t " << ref.t;
        EXPECT_EQ(h.hit(), ref.valid());
      }
      if (ref.valid()) ++on[ref.instance_id];
    }
    // Every object is hit by a fair share of the rays.
    EXPECT_GT(on[s.walker], 100u);
    EXPECT_GT(on[s.ground], 100u);
    EXPECT_GT(on[s.kicker], 100u);
  }
}

TEST(ApiQueries, AnyHitIsWhetherTheNearestHitLiesOnTheRay) {
  Scenes s;
  std::vector<api::Ray> rays = query_rays();
  // Also each camera ray cut short just before and just after its nearest
  // hit: blocked only in the second case.
  const std::size_t camera_rays = static_cast<std::size_t>(kW / 2) * static_cast<std::size_t>(kH / 2);
  for (std::size_t i = 0; i < camera_rays; ++i) {
    const Hit ref = testing_support::nearest(s.soup, to_internal(rays[i]), rt::TriangleTest::kFast);
    if (!ref.valid()) continue;
    api::Ray before = rays[i], after = rays[i];
    before.t_max = 0.99f * ref.t;
    after.t_max = 1.01f * ref.t;
    rays.push_back(before);
    rays.push_back(after);
  }
  std::vector<std::uint8_t> blocked(rays.size(), 7);
  ASSERT_TRUE(s.world.occluded(rays, blocked).ok());
  std::size_t blocked_count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool expected = testing_support::any_hit(s.soup, to_internal(rays[i]), rt::TriangleTest::kFast);
    ASSERT_EQ(blocked[i], expected ? 1 : 0) << "ray " << i;
    const auto single = s.world.occluded(rays[i]);
    ASSERT_TRUE(single.ok());
    ASSERT_EQ(*single, expected) << "ray " << i;
    blocked_count += expected;
  }
  EXPECT_GT(blocked_count, rays.size() / 5);
  EXPECT_LT(blocked_count, rays.size() * 4 / 5);
}

TEST(ApiQueries, SeeTheLatestPoseWithOrWithoutAPassBetween) {
  Scenes s;
  const std::vector<api::Ray> rays = query_rays();
  std::vector<api::RayHit> before(rays.size());
  ASSERT_TRUE(s.world.intersect(rays, before).ok());
  // A new pose, queried at once: the reference posed alike.
  ASSERT_TRUE(s.world.pose_at(s.walker, "kick", 0.3).ok());
  const auto moved = Scenes::reference({{"kick", 0.3, Affine3::identity()},
                                        {"kick", 0.55, Scenes::translation(0.8f, 0.0f, -0.3f)}});
  const auto check = [&](const char* when) {
    std::vector<api::RayHit> hits(rays.size());
    ASSERT_TRUE(s.world.intersect(rays, hits).ok());
    std::size_t changed = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const sinew::Ray ray = to_internal(rays[i]);
      const Hit ref = testing_support::nearest(moved, ray, rt::TriangleTest::kFast);
      const Hit ours{hits[i].t, hits[i].u, hits[i].v, hits[i].triangle, hits[i].instance};
      ASSERT_TRUE(testing_support::same_nearest(ours, ref, moved, ray, rt::TriangleTest::kFast))
          << when << " ray " << i;
      changed += hits[i].t != before[i].t;
    }
    EXPECT_GT(changed, 50u) << when;
  };
  check("after pose_at");
  // A pass without the fallback leaves the escaped triangles out of the
  // frame state; the next query must not trust it.
  api::PassDesc desc;
  desc.width = kW;
  desc.height = kH;
  desc.fallback = false;
  desc.threads = 1;
  auto pass = api::RayTracePass::create(desc).value();
  Frame frame(kW, kH);
  api::PassInputs inputs;
  inputs.camera = testing_support::test_camera();
  const auto stats = pass.execute(s.world, inputs, frame.outputs());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  check("after a pass without the fallback");
}

TEST(ApiQueries, BadRaysAreRefusedByNameAndNothingIsWritten) {
  Scenes s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    api::Ray ray;
    const char* says;
  };
  const Case cases[] = {
      {{{nan, 0, 0}, {0, 0, 1}}, "origin is not finite"},
      {{{0, 0, 0}, {0, kInf, 1}}, "direction is not finite"},
      {{{0, 0, 0}, {0, 0, 0}}, "direction is zero"},
      {{{0, 0, 0}, {0, 0, 1}, -1.0f}, "t_min"},
      {{{0, 0, 0}, {0, 0, 1}, nan}, "t_min"},
      {{{0, 0, 0}, {0, 0, 1}, 2.0f, 1.0f}, "t_max"},
      {{{0, 0, 0}, {0, 0, 1}, 0.0f, nan}, "t_max"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.says);
    const auto single = s.world.intersect(c.ray);
    ASSERT_FALSE(single.ok());
    EXPECT_EQ(single.error().code, api::ErrorCode::kInvalidArgument);
    EXPECT_NE(single.error().message.find(c.says), std::string::npos) << single.error().message;
    EXPECT_FALSE(s.world.occluded(c.ray).ok());
    // In a batch: named by index, and no answer written.
    const api::Ray batch[] = {api::Ray{{0, 1, 3}, {0, 0, -1}}, c.ray};
    api::RayHit hits[2];
    hits[0].t = -5.0f;
    const api::Status status = s.world.intersect(batch, hits);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.error().message.find("rays[1]"), std::string::npos) << status.error().message;
    EXPECT_EQ(hits[0].t, -5.0f);
    std::uint8_t blocked[2] = {9, 9};
    EXPECT_FALSE(s.world.occluded(batch, blocked).ok());
    EXPECT_EQ(blocked[0], 9);
  }
  // Spans that disagree.
  const api::Ray one[] = {api::Ray{}};
  api::RayHit two[2];
  const api::Status mismatch = s.world.intersect(one, two);
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.error().message.find("hits: 2 entries for 1 rays"), std::string::npos);
  // An empty range is no error: nothing lies on it.
  const auto empty = s.world.occluded(api::Ray{{0, 1, 3}, {0, 0, -1}, 1.0f, 1.0f});
  ASSERT_TRUE(empty.ok());
  EXPECT_FALSE(*empty);
}

// Instance ids hit in a frame's instance_id output.
std::vector<std::size_t> pixels_per_id(const Frame& f, std::size_t ids) {
  std::vector<std::size_t> seen(ids, 0);
  for (const std::uint32_t id : f.instance_id) {
    if (id != api::kNoHit) ++seen.at(id);
  }
  return seen;
}

TEST(ApiWorld, RemovedInstancesLeaveThePassAndTheQueriesAndTheirIdsAreNotReused) {
  Scenes s;
  api::PassDesc desc;
  desc.width = kW;
  desc.height = kH;
  desc.outputs = testing_support::kEveryOutput;
  desc.threads = 2;
  auto pass = api::RayTracePass::create(desc).value();
  api::PassInputs inputs;
  inputs.camera = testing_support::test_camera();
  const api::Light light = testing_support::test_light();
  inputs.lights = std::span<const api::Light>(&light, 1);

  Frame all(kW, kH);
  ASSERT_TRUE(pass.execute(s.world, inputs, all.outputs()).ok());
  EXPECT_GT(pixels_per_id(all, 3)[s.walker], 50u);

  ASSERT_TRUE(s.world.remove(s.walker).ok());
  EXPECT_EQ(s.world.instance_count(), 2u);
  Frame without(kW, kH);
  ASSERT_TRUE(pass.execute(s.world, inputs, without.outputs()).ok());
  const auto seen = pixels_per_id(without, 3);
  EXPECT_EQ(seen[s.walker], 0u);
  EXPECT_GT(seen[s.ground], 100u);
  EXPECT_GT(seen[s.kicker], 50u);
  // Queries agree with a reference of the other two alone.
  const std::vector<api::Ray> rays = query_rays();
  std::vector<testing_support::SoupTriangle> rest;
  for (const auto& tri : s.soup) {
    if (tri.instance_id != s.walker) rest.push_back(tri);
  }
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const auto h = s.world.intersect(rays[i]);
    ASSERT_TRUE(h.ok());
    const sinew::Ray ray = to_internal(rays[i]);
    const Hit ours{h->t, h->u, h->v, h->triangle, h->instance};
    ASSERT_TRUE(testing_support::same_nearest(ours, testing_support::nearest(rest, ray, rt::TriangleTest::kFast),
                                              rest, ray, rt::TriangleTest::kFast))
        << "ray " << i;
  }

  // The id is retired: every call naming it is refused, a second removal too.
  for (const api::Status& status :
       {s.world.remove(s.walker), s.world.pose_at(s.walker, "walk", 0.1), s.world.play_cycle(s.walker, "walk", 1, 0),
        s.world.set_transform(s.walker, api::Matrix3x4::identity())}) {
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.error().code, api::ErrorCode::kNotFound);
    EXPECT_NE(status.error().message.find("removed"), std::string::npos) << status.error().message;
  }
  EXPECT_EQ(s.world.remove(99).error().code, api::ErrorCode::kNotFound);
  const api::Character character = load_mannequin();
  const auto again = s.world.add_instance(character);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, 3u);

  // Emptied: the background alone, queries miss; refilled: what a fresh
  // world with the same content renders (ids aside).
  for (const api::InstanceId id : {s.ground, s.kicker, *again}) ASSERT_TRUE(s.world.remove(id).ok());
  EXPECT_EQ(s.world.instance_count(), 0u);
  Frame empty(kW, kH);
  ASSERT_TRUE(pass.execute(s.world, inputs, empty.outputs()).ok());
  EXPECT_TRUE(std::all_of(empty.instance_id.begin(), empty.instance_id.end(),
                          [](std::uint32_t id) { return id == api::kNoHit; }));
  EXPECT_FALSE(s.world.intersect(rays[kW / 2 * 10]).value().hit());
  EXPECT_FALSE(s.world.occluded(rays[kW / 2 * 10]).value());

  const auto back = s.world.add_instance(character);
  ASSERT_TRUE(back.ok());
  ASSERT_TRUE(s.world.pose_at(*back, "kick", 0.2).ok());
  api::World fresh = api::World::create().value();
  const auto only = fresh.add_instance(character).value();
  ASSERT_TRUE(fresh.pose_at(only, "kick", 0.2).ok());
  Frame refilled(kW, kH), reference(kW, kH);
  ASSERT_TRUE(pass.execute(s.world, inputs, refilled.outputs()).ok());
  ASSERT_TRUE(pass.execute(fresh, inputs, reference.outputs()).ok());
  EXPECT_EQ(refilled.rgba8, reference.rgba8);
  EXPECT_EQ(refilled.triangle_id, reference.triangle_id);
  EXPECT_EQ(std::memcmp(refilled.depth.data(), reference.depth.data(), refilled.depth.size() * sizeof(float)), 0);
  EXPECT_GT(pixels_per_id(refilled, 6)[*back], 100u);
}

}  // namespace
}  // namespace sinew
