// World's ray queries and instance removal (include/sinew/world.h) against
// an independent reference: every posed triangle of the same instances in a
// flat list, intersected one by one (tests/support/brute_force.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "content/mannequin/mannequin.h"
#include "raytrace/traverse/traversal.h"
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

// A batch skins only the instances its rays reach (lazy skinning): after a
// batch that reaches no character, single rays and batches aimed at them
// still see every posed triangle.
TEST(ApiQueries, AfterABatchThatReachesNoCharacterEveryQuerySeesThemAll) {
  Scenes s;
  const std::vector<api::Ray> away = {{{-2.5f, 1.0f, 2.5f}, {0.0f, 1.0f, 0.0f}, 0.0f, 1.0f},
                                      {{2.5f, 1.0f, 2.5f}, {0.0f, 1.0f, 0.0f}, 0.0f, 1.0f}};
  std::vector<api::RayHit> none(away.size());
  ASSERT_TRUE(s.world.intersect(away, none).ok());
  for (const api::RayHit& h : none) EXPECT_FALSE(h.hit());
  const api::Ray at_kicker{{0.8f, 1.0f, 3.0f}, {0.0f, 0.0f, -1.0f}};
  const api::Ray at_walker{{0.0f, 1.0f, 3.0f}, {0.0f, 0.0f, -1.0f}};
  const auto single = s.world.intersect(at_kicker);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->instance, s.kicker);
  ASSERT_TRUE(s.world.intersect(away, none).ok());
  const std::vector<api::Ray> both = {at_walker, at_kicker};
  std::vector<api::RayHit> hits(both.size());
  ASSERT_TRUE(s.world.intersect(both, hits).ok());
  for (std::size_t i = 0; i < both.size(); ++i) {
    const sinew::Ray ray = to_internal(both[i]);
    const Hit ref = testing_support::nearest(s.soup, ray, rt::TriangleTest::kFast);
    ASSERT_TRUE(ref.valid());
    const Hit ours{hits[i].t, hits[i].u, hits[i].v, hits[i].triangle, hits[i].instance};
    EXPECT_TRUE(testing_support::same_nearest(ours, ref, s.soup, ray, rt::TriangleTest::kFast)) << i;
  }
  EXPECT_EQ(hits[0].instance, s.walker);
  EXPECT_EQ(hits[1].instance, s.kicker);
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

// The reference hit over the soup's triangles whose instance's mask shares
// a bit with the ray's.
std::vector<testing_support::SoupTriangle> unmasked(const std::vector<testing_support::SoupTriangle>& soup,
                                                    const std::uint32_t* masks, std::uint32_t ray_mask) {
  std::vector<testing_support::SoupTriangle> kept;
  for (const auto& tri : soup) {
    if ((masks[tri.instance_id] & ray_mask) != 0) kept.push_back(tri);
  }
  return kept;
}

TEST(ApiQueries, MasksSkipInstancesAsBruteForceOverTheUnmaskedOnesDoes) {
  Scenes s;
  std::vector<api::Ray> rays = query_rays();
  std::mt19937 g(5);
  std::uniform_int_distribution<std::uint32_t> bits(0, 7);
  std::uint32_t masks[3] = {api::kAllMaskBits, api::kAllMaskBits, api::kAllMaskBits};
  // A default ray and default masks: every object, as before.
  EXPECT_EQ(api::Ray{}.mask, api::kAllMaskBits);
  EXPECT_EQ(api::InstanceDesc{}.mask, api::kAllMaskBits);
  EXPECT_EQ(api::StaticMeshDesc{}.mask, api::kAllMaskBits);
  std::size_t skipped_hits = 0, kept_hits = 0;
  for (int round = 0; round < 4; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    // Random masks (three bits, so every overlap and none happen), set
    // between queries: no pass or pose in between.
    if (round > 0) {
      for (std::uint32_t& m : masks) m = bits(g);
      for (const api::InstanceId id : {s.walker, s.ground, s.kicker}) ASSERT_TRUE(s.world.set_mask(id, masks[id]).ok());
    }
    for (api::Ray& r : rays) r.mask = round == 0 ? api::kAllMaskBits : bits(g);
    std::vector<api::RayHit> hits(rays.size());
    std::vector<std::uint8_t> blocked(rays.size(), 7);
    ASSERT_TRUE(s.world.intersect(rays, hits).ok());
    ASSERT_TRUE(s.world.occluded(rays, blocked).ok());
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const sinew::Ray ray = to_internal(rays[i]);
      const auto kept = unmasked(s.soup, masks, rays[i].mask);
      const Hit ref = testing_support::nearest(kept, ray, rt::TriangleTest::kFast);
      const Hit ours{hits[i].t, hits[i].u, hits[i].v, hits[i].triangle, hits[i].instance};
      ASSERT_TRUE(testing_support::same_nearest(ours, ref, kept, ray, rt::TriangleTest::kFast))
          << "ray " << i << " mask " << rays[i].mask << ": instance " << hits[i].instance << " t " << hits[i].t
          << ", brute force: instance " << ref.instance_id << " t " << ref.t;
      const auto single = s.world.intersect(rays[i]);
      ASSERT_TRUE(single.ok());
      EXPECT_EQ(single->instance, hits[i].instance);
      EXPECT_EQ(single->t, hits[i].t);
      const bool expected = testing_support::any_hit(kept, ray, rt::TriangleTest::kFast);
      ASSERT_EQ(blocked[i], expected ? 1 : 0) << "ray " << i;
      ASSERT_EQ(s.world.occluded(rays[i]).value(), expected) << "ray " << i;
      // Whether the mask changed the answer: the nearest over every object
      // lies on a masked one.
      const Hit any_mask = testing_support::nearest(s.soup, ray, rt::TriangleTest::kFast);
      if (any_mask.valid()) {
        const bool masked_out = (masks[any_mask.instance_id] & rays[i].mask) == 0;
        skipped_hits += masked_out;
        kept_hits += !masked_out;
      }
    }
  }
  // The masks mattered, both ways.
  EXPECT_GT(skipped_hits, 300u);
  EXPECT_GT(kept_hits, 300u);

  // Masks given at creation, and refused ids.
  const api::Character character = load_mannequin();
  api::InstanceDesc hidden;
  hidden.mask = 0x10u;
  api::World world = api::World::create().value();
  const api::InstanceId id = world.add_instance(character, hidden).value();
  const api::InstanceId floor =
      world.add_static_mesh({kQuad, kQuadIndices, {0.5f, 0.5f, 0.5f}, 0x20u}).value();
  api::Ray down{{0.0f, 5.0f, 2.5f}, {0.0f, -1.0f, 0.0f}};  // misses the mannequin, meets the floor
  EXPECT_EQ(world.intersect(down).value().instance, floor);
  down.mask = 0x10u;
  EXPECT_FALSE(world.intersect(down).value().hit());
  EXPECT_FALSE(world.occluded(down).value());
  down.mask = 0x30u;
  EXPECT_EQ(world.intersect(down).value().instance, floor);
  EXPECT_EQ(world.set_mask(99, 1).error().code, api::ErrorCode::kNotFound);
  ASSERT_TRUE(world.remove(id).ok());
  const api::Status removed = world.set_mask(id, 1);
  ASSERT_FALSE(removed.ok());
  EXPECT_EQ(removed.error().code, api::ErrorCode::kNotFound);
  EXPECT_NE(removed.error().message.find("removed"), std::string::npos) << removed.error().message;
}

// A masked instance costs nothing past the top level: the query enters
// none of its objects and tests none of its triangles.
TEST(ApiQueries, MaskedInstancesAreNeverEntered) {
  const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(pack.model().mesh, pack.fuzzy()).value();
  const std::uint32_t a = scene.add_instance(character).value();
  const std::uint32_t b = scene.add_instance(character).value();
  ASSERT_TRUE(scene.set_bones(b, testing_support::clip_pose(pack.model(), "walk", 0.3,
                                                            Scenes::translation(0.3f, 0.0f, 0.0f))).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame({}, jobs).ok());
  ASSERT_TRUE(scene.set_mask(a, 1u).ok());
  ASSERT_TRUE(scene.set_mask(b, 2u).ok());
  const std::vector<api::Ray> rays = query_rays();
  rt::TraversalCounters none, all;
  std::size_t hits = 0;
  for (const api::Ray& r : rays) {
    EXPECT_FALSE(rt::intersect(scene, to_internal(r), 4u, rt::TriangleTest::kFast, &none).valid());
    EXPECT_FALSE(rt::occluded(scene, to_internal(r), 4u, rt::TriangleTest::kFast, &none));
    hits += rt::intersect(scene, to_internal(r), 3u, rt::TriangleTest::kFast, &all).valid();
  }
  EXPECT_EQ(none.object_visits, 0u);
  EXPECT_EQ(none.triangle_tests, 0u);
  EXPECT_GT(all.object_visits, 500u);
  EXPECT_GT(hits, 200u);
}

glm::dvec3 unit_normal(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  return glm::normalize(glm::cross(glm::dvec3(p1) - glm::dvec3(p0), glm::dvec3(p2) - glm::dvec3(p0)));
}

TEST(ApiQueries, HitsCarryTheWindingNormalOfThePosedTriangleAndItsMaterial) {
  Scenes s;
  const std::vector<api::Ray> rays = query_rays();
  const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  const SkinnedMesh& mesh = pack.model().mesh;
  std::vector<api::RayHit> hits(rays.size());
  ASSERT_TRUE(s.world.intersect(rays, hits).ok());
  std::size_t on_ground = 0, on_characters = 0, from_behind = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const api::RayHit& h = hits[i];
    if (!h.hit()) {
      EXPECT_EQ(h.material, api::kNoHit);
      continue;
    }
    const api::Float3 n = h.geometric_normal;
    EXPECT_NEAR(n.x * n.x + n.y * n.y + n.z * n.z, 1.0f, 1e-5f);
    EXPECT_EQ(h.uv.x, 0.0f);  // neither the mannequin nor the ground has UVs
    EXPECT_EQ(h.uv.y, 0.0f);
    if (h.instance == s.ground) {
      // By hand: the quad's triangles (0, 2, 1) and (1, 2, 3) run
      // counter-clockwise seen from above.
      EXPECT_EQ(n.x, 0.0f);
      EXPECT_EQ(n.y, 1.0f);
      EXPECT_EQ(n.z, 0.0f);
      EXPECT_EQ(h.material, 0u);
      ++on_ground;
      continue;
    }
    // The posed triangle of the reference's soup, by winding.
    const auto tri = std::find_if(s.soup.begin(), s.soup.end(), [&](const testing_support::SoupTriangle& t) {
      return t.instance_id == h.instance && t.triangle_id == h.triangle;
    });
    ASSERT_NE(tri, s.soup.end());
    const glm::dvec3 expected = unit_normal(tri->p0, tri->p1, tri->p2);
    EXPECT_NEAR(n.x, expected.x, 1e-5);
    EXPECT_NEAR(n.y, expected.y, 1e-5);
    EXPECT_NEAR(n.z, expected.z, 1e-5);
    EXPECT_EQ(h.material, mesh.triangle_material[h.triangle]);
    from_behind += n.x * rays[i].direction.x + n.y * rays[i].direction.y + n.z * rays[i].direction.z > 0.0f;
    ++on_characters;
  }
  EXPECT_GT(on_ground, 100u);
  EXPECT_GT(on_characters, 150u);
  EXPECT_GT(from_behind, 10u);  // rays from inside a character meet back faces: the normal is not flipped
}

// The mannequin with hand-made texture coordinates, uv = (x, y) of the
// vertex at bind pose, as a pack: a hit's UV is then the (x, y) of its
// point carried back to bind pose.
const std::string& uv_mannequin_pack_path() {
  static const testing_support::BakedModel baked = [] {
    character::Model model = content::make_mannequin().value();
    for (const Vec3& p : model.mesh.positions) model.mesh.uvs.push_back(Vec2(p.x, p.y));
    return testing_support::bake_over_idle(std::move(model));
  }();
  static const testing_support::TemporaryPackFile pack(baked, "uv_mannequin");
  return pack.path();
}

TEST(ApiQueries, HitsCarryTheirUvAndTheNormalTurnsWithTheBones) {
  const api::Character character = api::Character::load(uv_mannequin_pack_path()).value();
  api::World world = api::World::create().value();
  api::InstanceDesc desc;
  desc.driver = api::Driver::kHost;
  const api::InstanceId id = world.add_instance(character, desc).value();
  const character::Pack pack = character::Pack::open(uv_mannequin_pack_path()).value();
  const SkinnedMesh& mesh = pack.model().mesh;
  // Every bone turned a quarter about +X, (x, y, z) -> (x, -z, y), and
  // moved by (1, 2, 3): the mannequin lies along +Z.
  api::Matrix3x4 turn;
  const float rows[3][4] = {{1, 0, 0, 1}, {0, 0, -1, 2}, {0, 1, 0, 3}};
  std::memcpy(turn.m, rows, sizeof rows);
  const std::vector<api::Matrix3x4> bones(character.bone_count(), turn);
  ASSERT_TRUE(world.set_bone_matrices(id, bones).ok());
  const auto posed = [&](const Vec3& p) { return Vec3(p.x + 1.0f, -p.z + 2.0f, p.y + 3.0f); };
  const auto unposed = [&](const Vec3& q) { return Vec3(q.x - 1.0f, q.z - 3.0f, -(q.y - 2.0f)); };
  // Rays from around each of a spread of vertices towards it.
  std::mt19937 g(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::size_t checked = 0;
  for (std::size_t v = 0; v < mesh.positions.size(); v += 7) {
    const Vec3 target = posed(mesh.positions[v]);
    const Vec3 from = target + 3.0f * Vec3(unit(g), unit(g), unit(g));
    const Vec3 d = target - from;
    const auto h = world.intersect(api::Ray{{from.x, from.y, from.z}, {d.x, d.y, d.z}});
    ASSERT_TRUE(h.ok());
    if (!h->hit()) continue;
    const Vec3 at = unposed(from + h->t * d);
    EXPECT_NEAR(h->uv.x, at.x, 1e-4f) << "vertex " << v;
    EXPECT_NEAR(h->uv.y, at.y, 1e-4f) << "vertex " << v;
    // The bind-pose triangle's normal, turned as the bones turn it.
    const auto& c = mesh.triangles[h->triangle];
    const Vec3 &p0 = mesh.positions[c[0]], &p1 = mesh.positions[c[1]], &p2 = mesh.positions[c[2]];
    const glm::dvec3 n = unit_normal(p0, p1, p2);
    // The posed corners are skinned in float: each coordinate off by a few
    // units in the last place of the posed magnitudes (up to about 5),
    // which turns the normal by up to that over the triangle's height.
    const glm::dvec3 e1 = glm::dvec3(p1) - glm::dvec3(p0), e2 = glm::dvec3(p2) - glm::dvec3(p0);
    const double rounding = 4.0 * 0x1.0p-23 * 5.0;
    const double tolerance =
        1e-6 + 2.0 * rounding * (glm::length(e1) + glm::length(e2)) / glm::length(glm::cross(e1, e2));
    EXPECT_NEAR(h->geometric_normal.x, n.x, tolerance);
    EXPECT_NEAR(h->geometric_normal.y, -n.z, tolerance);
    EXPECT_NEAR(h->geometric_normal.z, n.y, tolerance);
    EXPECT_EQ(h->material, mesh.triangle_material[h->triangle]);
    ++checked;
  }
  EXPECT_GT(checked, 50u);
}

}  // namespace
}  // namespace sinew
