// Group frusta (cull/group_frusta.h) never cull a triangle that a ray of
// the group hits, by either triangle test, for rays from an apex and for
// rays ending near one, at small and large coordinates; and they do cull
// most triangles beside a narrow group.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "raytrace/cull/group_frusta.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"
#include "tests/support/slab_test.h"

namespace sinew {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }
float signed_unit(std::mt19937& g) { return 2.0f * unit(g) - 1.0f; }
Vec3 random_vec(std::mt19937& g) { return Vec3(signed_unit(g), signed_unit(g), signed_unit(g)); }

bool hits(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  rt::TriangleHit h;
  if (rt::intersect_triangle_fast(ray, ray.t_max, p0, p1, p2, h)) return true;
  return rt::intersect_triangle_watertight(rt::prepare_watertight(ray), ray, ray.t_max, p0, p1, p2, h);
}

// A 4x2 block of directions around `centre`, `spread` apart (a pixel's angle).
void block_directions(const Vec3& centre, float spread, std::mt19937& g, float (&q)[3][8]) {
  const Vec3 c = glm::normalize(centre);
  const Vec3 u = glm::normalize(glm::cross(c, std::fabs(c.z) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0)));
  const Vec3 v = glm::cross(c, u);
  const float scale = 0.5f + 2.0f * unit(g);  // directions need not be unit
  for (int lane = 0; lane < 8; ++lane) {
    const float x = static_cast<float>(lane % 4) - 1.5f, y = static_cast<float>(lane / 4) - 0.5f;
    const Vec3 d = scale * (c + spread * (x * u + y * v));
    q[0][lane] = d.x;
    q[1][lane] = d.y;
    q[2][lane] = d.z;
  }
}

// Whether the ray's points at t in [t_min, t_max] meet the box, in double.
bool enters(const Ray& ray, const Aabb& box) {
  return testing_support::ray_enters_box(ray.origin, ray.direction, ray.t_min, ray.t_max, box);
}

struct Tally {
  int hit_triangles = 0;
  int culled = 0;
  int tried = 0;
  int boxes_entered = 0;
  int boxes_culled = 0;
};

// Triangles around the group's rays, from far off to straddling them; every
// one a lane hits must be reached. The rays leave the apex along `along`, t >= 0;
// `segments`: they end at t_max = 1 (shadow rays from a point light, their
// lengths scaled by 1 to 51) and the frustum gets its far plane.
// `batched`: the frustum is built by set_groups, as lane 5 of a block of
// eight groups whose other lanes hold other directions (or no lanes).
void check_group(const Vec3& apex, const float (&along)[3][8], std::uint32_t lanes, bool segments,
                 bool batched, std::mt19937& g, Tally& tally) {
  std::array<Ray, 8> rays;
  float q[3][8];
  alignas(32) float reach[8];
  for (int lane = 0; lane < 8; ++lane) {
    const float length = segments ? 1.0f + 50.0f * unit(g) : 1.0f;
    for (int a = 0; a < 3; ++a) q[a][lane] = length * along[a][lane];
    rays[lane].origin = apex;
    rays[lane].direction = Vec3(q[0][lane], q[1][lane], q[2][lane]);
    rays[lane].t_min = 0.0f;
    rays[lane].t_max = segments ? 1.0f : kInf;
    reach[lane] = rays[lane].t_max;
  }
  rt::GroupFrusta<16> frusta;
  std::uint32_t tested = 1u;
  if (!batched) {
    frusta.reset(apex, 1);
    frusta.set_group(0, q, lanes, segments ? reach : nullptr);
  } else {
    // Groups 0-7 and 8-15: the tested one is group 5 and group 13 (its
    // directions negated and given with sign -1), among others.
    constexpr int kTested = 5;
    float others[16][3][8], negated[3][8];
    for (auto& other : others) block_directions(random_vec(g), 0.01f * unit(g), g, other);
    for (int a = 0; a < 3; ++a) {
      for (int lane = 0; lane < 8; ++lane) negated[a][lane] = -q[a][lane];
    }
    frusta.reset(apex, 16);
    const auto lanes_of = [&](int group) { return group == 2 ? 0u : group % kTested == 1 ? 0x7Fu : lanes; };
    const auto directions = [&](int group) -> const float (&)[3][8] {
      return group == kTested ? q : group == 8 + kTested ? negated : others[group];
    };
    if (segments) {
      const auto reach_of = [&](int, float* out) { std::copy(reach, reach + 8, out); };
      frusta.set_groups<true>(0xFFu, 1.0f, directions, lanes_of, reach_of);
      frusta.set_groups<true>(0xFF00u, -1.0f, directions, lanes_of, reach_of);
    } else {
      const auto no_reach = [](int, float*) {};
      frusta.set_groups<false>(0xFFu, 1.0f, directions, lanes_of, no_reach);
      frusta.set_groups<false>(0xFF00u, -1.0f, directions, lanes_of, no_reach);
    }
    tested = 1u << kTested | 1u << (8 + kTested);
  }
  for (int trial = 0; trial < 400; ++trial) {
    const int lane = static_cast<int>(g() % 8);
    const Ray& r = rays[lane];
    // A point along a lane's ray (for segments, also beyond their ends: the
    // far plane's side), the triangle around it at a random size, shifted
    // sideways by up to a few of its sizes.
    const float t = segments ? 1.3f * unit(g) : 0.5f + 40.0f * unit(g);
    const Vec3 at = r.origin + t * r.direction;
    const float size = glm::length(r.direction) * (0.001f + 0.2f * unit(g) * unit(g)) * (segments ? 1.0f : t);
    const Vec3 shift = size * 3.0f * unit(g) * random_vec(g);
    const Vec3 p0 = at + shift + size * random_vec(g);
    const Vec3 p1 = at + shift + size * random_vec(g);
    const Vec3 p2 = at + shift + size * random_vec(g);
    const std::uint32_t reached_groups = frusta.reached(p0, p1, p2, tested);
    // Built one way or the other, with either sign, the same rays.
    ASSERT_TRUE(reached_groups == 0 || reached_groups == tested) << reached_groups;
    const bool reached = reached_groups != 0;
    ++tally.tried;
    if (!reached) ++tally.culled;
    // A box about the same place (an object's box): never culled when a
    // lane's ray enters it.
    const Vec3 half = size * Vec3(unit(g), unit(g), unit(g));
    const Aabb box{at + shift - half, at + shift + half};
    const std::uint32_t box_groups = frusta.box_reached(box, tested);
    ASSERT_TRUE(box_groups == 0 || box_groups == tested) << box_groups;
    if (box_groups == 0) ++tally.boxes_culled;
    for (int l = 0; l < 8; ++l) {
      if (!(lanes >> l & 1u) || !enters(rays[l], box)) continue;
      ++tally.boxes_entered;
      ASSERT_NE(box_groups, 0u) << "lane " << l << " enters a culled box; apex (" << apex.x << "," << apex.y << ","
                                << apex.z << ") trial " << trial;
      break;
    }
    for (int l = 0; l < 8; ++l) {
      if (!(lanes >> l & 1u) || !hits(rays[l], p0, p1, p2)) continue;
      ++tally.hit_triangles;
      ASSERT_TRUE(reached) << "lane " << l << " hits a culled triangle; apex (" << apex.x << "," << apex.y << ","
                           << apex.z << ") trial " << trial;
      break;
    }
  }
}

TEST(GroupFrusta, EveryHitTriangleIsReachedFromTheApex) {
  std::mt19937 g(3);
  Tally tally;
  for (const float offset : {0.0f, 50.0f, 3000.0f}) {
    for (int group = 0; group < 60; ++group) {
      const Vec3 apex = offset * random_vec(g) + random_vec(g);
      float q[3][8];
      block_directions(random_vec(g), 0.0007f * (1.0f + 4.0f * unit(g)), g, q);
      const std::uint32_t lanes = group % 5 == 0 ? (g() & 0xFFu) | 1u : 0xFFu;
      for (const bool batched : {false, true}) {
        check_group(apex, q, lanes, false, batched, g, tally);
        if (HasFatalFailure()) return;
      }
    }
  }
  EXPECT_GT(tally.hit_triangles, tally.tried / 10);
  // Most triangles beside a narrow group are culled: the test has teeth.
  EXPECT_GT(tally.culled, tally.tried / 3) << tally.culled << " of " << tally.tried;
  EXPECT_GT(tally.boxes_entered, tally.tried / 10);
  EXPECT_GT(tally.boxes_culled, tally.tried / 4) << tally.boxes_culled << " of " << tally.tried;
}

TEST(GroupFrusta, EveryHitTriangleIsReachedBySegmentsFromTheApex) {
  std::mt19937 g(5);
  Tally tally;
  for (const float offset : {0.0f, 80.0f, 2000.0f}) {
    for (int group = 0; group < 60; ++group) {
      const Vec3 light = offset * random_vec(g) + random_vec(g);
      float q[3][8];
      block_directions(random_vec(g), 0.002f * (1.0f + 4.0f * unit(g)), g, q);
      for (const bool batched : {false, true}) {
        check_group(light, q, 0xFFu, true, batched, g, tally);
        if (HasFatalFailure()) return;
      }
    }
  }
  EXPECT_GT(tally.hit_triangles, tally.tried / 10);
  EXPECT_GT(tally.culled, tally.tried / 4) << tally.culled << " of " << tally.tried;
  EXPECT_GT(tally.boxes_entered, tally.tried / 10);
  EXPECT_GT(tally.boxes_culled, tally.tried / 5) << tally.boxes_culled << " of " << tally.tried;
}

// A 32x16-pixel packet from `apex` (offset from the origin by up to
// `offset`) about a random centre, `pixel` apart: rays, or segments to
// t = 1 of lengths 1 to 41; with `partial`, random lanes of each group.
// With a radius, each segment starts at a random point within it of the
// apex (an area light's sample) and ends where the one from the apex would:
// q holds the ends relative to the apex, as the packet gives them.
struct Packet {
  Vec3 apex{0.0f};
  float radius = 0.0f;
  float pixel = 0.0f;
  float q[64][3][8];
  alignas(32) float reach[64][8];
  std::uint32_t lanes[64];
  std::array<Ray, 512> rays;
};

void make_packet(float offset, bool segments, bool partial, std::mt19937& g, Packet& p, float radius = 0.0f) {
  p.apex = offset * random_vec(g) + random_vec(g);
  p.radius = radius;
  const Vec3 c = glm::normalize(random_vec(g) + Vec3(0.0f, 0.0f, 1e-3f));
  const Vec3 u = glm::normalize(glm::cross(c, std::fabs(c.z) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0)));
  const Vec3 v = glm::cross(c, u);
  p.pixel = 0.0005f * (1.0f + 6.0f * unit(g));
  for (int group = 0; group < 64; ++group) {
    p.lanes[group] = partial ? (g() & 0xFFu) | 1u : 0xFFu;
    for (int lane = 0; lane < 8; ++lane) {
      const float x = static_cast<float>(4 * (group % 8) + lane % 4) - 15.5f;
      const float y = static_cast<float>(2 * (group / 8) + lane / 4) - 7.5f;
      const float length = segments ? 1.0f + 40.0f * unit(g) : 1.0f + unit(g);
      const Vec3 d = length * (c + p.pixel * (x * u + y * v));
      p.q[group][0][lane] = d.x;
      p.q[group][1][lane] = d.y;
      p.q[group][2][lane] = d.z;
      p.reach[group][lane] = segments ? 1.0f : kInf;
      Ray& r = p.rays[static_cast<std::size_t>(8 * group + lane)];
      r.origin = p.apex;
      r.direction = d;
      if (radius > 0.0f) {
        Vec3 w = random_vec(g);
        while (glm::dot(w, w) > 1.0f) w = random_vec(g);
        // Some on the ball's surface, the farthest a sample lies.
        if (g() % 4 == 0) w = glm::normalize(w);
        r.origin = p.apex + radius * w;
        r.direction = (p.apex + d) - r.origin;
      }
      r.t_min = 0.0f;
      r.t_max = p.reach[group][lane];
    }
  }
}

// The packet's frusta: each group's own (unless `slabs`), then, with
// `bound`, the packet's bound and the groups' slabs in its basis.
void build_frusta(const Packet& p, bool segments, bool slabs, bool bound, rt::GroupFrusta<64>& frusta) {
  frusta.reset(p.apex, 64, p.radius);
  frusta.use_slabs(slabs);
  const auto directions = [&](int group) -> const float (&)[3][8] { return p.q[group]; };
  const auto lanes_of = [&](int group) { return p.lanes[group]; };
  const auto reach_of = [&](int group, float* out) { std::copy(p.reach[group], p.reach[group] + 8, out); };
  const std::uint64_t all = ~std::uint64_t{0};
  if (segments) {
    if (!slabs) frusta.set_groups<true>(all, 1.0f, directions, lanes_of, reach_of);
    if (bound) frusta.set_bound<true>(all, 1.0f, directions, lanes_of, reach_of);
  } else {
    if (!slabs) frusta.set_groups<false>(all, 1.0f, directions, lanes_of, reach_of);
    if (bound) frusta.set_bound<false>(all, 1.0f, directions, lanes_of, reach_of);
  }
}

// A triangle about a random lane's ray, or beside the packet by up to its
// width, at a random size.
std::array<Vec3, 3> triangle_near(const Packet& p, bool segments, std::mt19937& g) {
  const int k = static_cast<int>(g() % 512);
  const Ray& r = p.rays[static_cast<std::size_t>(k)];
  const float t = segments ? 1.3f * unit(g) : 0.5f + 30.0f * unit(g);
  const Vec3 at = r.origin + t * r.direction;
  const float width = 16.0f * p.pixel * glm::length(r.direction) * (segments ? 1.0f : t);
  const float size = width * (0.005f + 0.3f * unit(g) * unit(g));
  const Vec3 shift = 1.5f * width * unit(g) * random_vec(g);
  const Vec3 p0 = at + shift + size * random_vec(g);
  const Vec3 p1 = at + shift + size * random_vec(g);
  const Vec3 p2 = at + shift + size * random_vec(g);
  return {p0, p1, p2};
}

// A 32x16-pixel packet (64 groups of 4x2 pixels, the most a packet holds) with its own frustum
// (set_bound) tested before the groups': a triangle some lane hits is still
// reached by that lane's group, from an apex near and far from the origin,
// for rays and for segments ending at their lane's reach (far plane), and
// with lanes missing from the groups; with the groups' own frusta and with
// their slabs in the packet's basis alone (use_slabs, shadow packets). The
// triangle's box (a leaf's box, raytrace/scene/leaf_boxes.h) reaches every
// group the triangle reaches, and the boxes are culled too, by the packet
// and by single groups.
TEST(GroupFrusta, ThePacketFrustumNeverCullsATriangleALaneHits) {
  for (const bool slabs : {false, true}) {
  SCOPED_TRACE(slabs ? "slabs" : "own frusta");
  std::mt19937 g(11);
  int tried = 0, hit = 0, culled = 0, some_groups = 0, boxes_culled = 0, boxes_some_groups = 0;
  for (const bool segments : {false, true}) {
    for (const float offset : {0.0f, 60.0f, 4000.0f}) {
      for (int packet = 0; packet < 20; ++packet) {
        Packet pk;
        make_packet(offset, segments, packet % 4 == 0, g, pk);
        const Vec3& apex = pk.apex;
        rt::GroupFrusta<64> frusta;
        // With slabs the groups' own frusta are not built: the slabs alone cull.
        build_frusta(pk, segments, slabs, true, frusta);
        if (slabs) {
          ASSERT_EQ(frusta.slab_groups(), ~std::uint64_t{0});
        }
        for (int trial = 0; trial < 300; ++trial) {
          const auto [p0, p1, p2] = triangle_near(pk, segments, g);
          const std::uint64_t reached = frusta.reached(p0, p1, p2, ~std::uint64_t{0});
          ++tried;
          if (reached == 0) ++culled;
          if (reached != 0 && std::popcount(reached) < 32) ++some_groups;
          const Aabb box{glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2))};
          const std::uint64_t box_groups = frusta.box_reached(box, ~std::uint64_t{0});
          ASSERT_EQ(reached & ~box_groups, 0u) << "groups reach the triangle but not its box; apex (" << apex.x << ","
                                               << apex.y << "," << apex.z << ") packet " << packet << " trial " << trial;
          if (box_groups == 0) ++boxes_culled;
          if (box_groups != 0 && std::popcount(box_groups) < 32) ++boxes_some_groups;
          for (int lane = 0; lane < 512; ++lane) {
            if (!(pk.lanes[lane / 8] >> (lane % 8) & 1u) ||
                !hits(pk.rays[static_cast<std::size_t>(lane)], p0, p1, p2)) {
              continue;
            }
            ++hit;
            ASSERT_NE(reached >> (lane / 8) & 1u, 0u)
                << "lane " << lane << " hits a culled triangle; apex (" << apex.x << "," << apex.y << "," << apex.z
                << ") packet " << packet << " trial " << trial;
          }
        }
      }
    }
  }
  EXPECT_GT(hit, tried / 10);
  EXPECT_GT(culled, tried / 5) << culled << " of " << tried;
  // The groups cull, not only the packet: many reached triangles reach few groups.
  EXPECT_GT(some_groups, tried / 10) << some_groups << " of " << tried;
  EXPECT_GT(boxes_culled, tried / 5) << boxes_culled << " of " << tried;
  EXPECT_GT(boxes_some_groups, tried / 10) << boxes_some_groups << " of " << tried;
  }
}

// Segments from anywhere within a radius of the apex (an area light's
// samples) to ends a packet's frusta are built around: the tilted sides
// (tilt_side) never cull a triangle or a box a segment meets, with the
// groups' own frusta, with their slabs and with the packet's bound, near
// the origin and far from it; and they still cull most triangles beside
// the packet's shaft.
TEST(GroupFrusta, SegmentsFromWithinARadiusOfTheApexAreNeverCulled) {
  for (const bool slabs : {false, true}) {
    SCOPED_TRACE(slabs ? "slabs" : "own frusta");
    std::mt19937 g(29);
    int tried = 0, hit = 0, culled = 0, boxes_entered = 0, missed_from_apex = 0;
    for (const float offset : {0.0f, 60.0f, 4000.0f}) {
      for (int packet = 0; packet < 20; ++packet) {
        Packet pk;
        const float radius = 0.02f + 0.3f * unit(g);  // the ends lie 1 to 41 away
        make_packet(offset, true, packet % 4 == 0, g, pk, radius);
        rt::GroupFrusta<64> frusta, from_apex;
        build_frusta(pk, true, slabs, true, frusta);
        // The same ends as rays from the apex itself, for the test's teeth.
        Packet apex_only = pk;
        apex_only.radius = 0.0f;
        build_frusta(apex_only, true, slabs, true, from_apex);
        for (int trial = 0; trial < 300; ++trial) {
          const auto [p0, p1, p2] = triangle_near(pk, true, g);
          const std::uint64_t reached = frusta.reached(p0, p1, p2, ~std::uint64_t{0});
          const Aabb box{glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2))};
          const std::uint64_t box_groups = frusta.box_reached(box, ~std::uint64_t{0});
          ++tried;
          if (reached == 0) ++culled;
          for (int lane = 0; lane < 512; ++lane) {
            if (!(pk.lanes[lane / 8] >> (lane % 8) & 1u)) continue;
            const Ray& ray = pk.rays[static_cast<std::size_t>(lane)];
            if (enters(ray, box)) {
              ++boxes_entered;
              ASSERT_NE(box_groups >> (lane / 8) & 1u, 0u) << "lane " << lane << " enters a culled box; packet "
                                                            << packet << " trial " << trial << " offset " << offset;
            }
            if (!hits(ray, p0, p1, p2)) continue;
            ++hit;
            ASSERT_NE(reached >> (lane / 8) & 1u, 0u) << "lane " << lane << " hits a culled triangle; packet "
                                                       << packet << " trial " << trial << " offset " << offset;
            if ((from_apex.reached(p0, p1, p2, ~std::uint64_t{0}) >> (lane / 8) & 1u) == 0) ++missed_from_apex;
          }
        }
      }
    }
    EXPECT_GT(hit, tried / 10);
    EXPECT_GT(boxes_entered, tried / 10);
    EXPECT_GT(culled, tried / 10) << culled << " of " << tried;
    // Untilted frusta would cull triangles these segments hit.
    EXPECT_GT(missed_from_apex, hit / 50) << missed_from_apex << " of " << hit;
  }
}

// A radius needs the segments' ends: rays without a far plane, or ends
// within twice the radius of the apex, get no frustum and reach everything.
TEST(GroupFrusta, ARadiusWithoutFarEndsBuildsNoFrustum) {
  const Vec3 light(0.5f, 1.0f, -2.0f);
  float q[3][8] = {};
  alignas(32) float reach[8];
  for (int lane = 0; lane < 8; ++lane) {
    q[0][lane] = 0.01f * static_cast<float>(lane % 4);
    q[1][lane] = 0.01f * static_cast<float>(lane / 4);
    q[2][lane] = 1.0f;
    reach[lane] = 10.0f;
  }
  const Vec3 p0 = light + Vec3(3, 3, 5), p1 = light + Vec3(4, 3, 5), p2 = light + Vec3(3, 4, 5);
  rt::GroupFrusta<8> rays, near, segments;
  rays.reset(light, 1, 0.5f);
  rays.set_group(0, q, 0xFFu);
  EXPECT_FALSE(rays.any_plane());
  EXPECT_EQ(rays.reached(p0, p1, p2, 1u), 1u);
  near.reset(light, 1, 6.0f);
  near.set_group(0, q, 0xFFu, reach);
  EXPECT_FALSE(near.any_plane());
  EXPECT_EQ(near.reached(p0, p1, p2, 1u), 1u);
  // Ends well beyond it: a frustum, and the triangle off to the side is culled.
  segments.reset(light, 1, 0.5f);
  segments.set_group(0, q, 0xFFu, reach);
  EXPECT_TRUE(segments.any_plane());
  EXPECT_EQ(segments.reached(p0, p1, p2, 1u), 0u);
  // Near the light, one that the segment from light + (0.45, 0, 0.1) to
  // its end crosses (at z = 0.5, about (0.43, 0)) is reached, though rays
  // from the apex itself pass far from it.
  const Vec3 c0 = light + Vec3(0.38f, -0.02f, 0.5f), c1 = light + Vec3(0.47f, -0.02f, 0.5f),
             c2 = light + Vec3(0.38f, 0.07f, 0.5f);
  Ray crossing;
  crossing.origin = light + Vec3(0.45f, 0.0f, 0.1f);
  crossing.direction = light + Vec3(0.0f, 0.0f, 10.0f) - crossing.origin;
  crossing.t_min = 0.0f;
  crossing.t_max = 1.0f;
  ASSERT_TRUE(hits(crossing, c0, c1, c2));
  EXPECT_EQ(segments.reached(c0, c1, c2, 1u), 1u);
  rt::GroupFrusta<8> from_apex;
  from_apex.reset(light, 1);
  from_apex.set_group(0, q, 0xFFu, reach);
  EXPECT_EQ(from_apex.reached(c0, c1, c2, 1u), 0u);
}

// reached8 (a leaf's triangles eight at a time, traverse/large_packet.cpp)
// decides each triangle and group as reached() does with the groups' own
// frusta alone (the packet's bound is not its to test), and as reached()
// itself with slabs; for random batches of one to eight triangles, random
// lanes of the batch and random groups, near the origin and far from it.
TEST(GroupFrusta, ReachedEightAtATimeDecidesAsOneAtATime) {
  std::mt19937 g(23);
  int compared = 0, culled = 0, some_groups = 0;
  for (const bool slabs : {false, true}) {
    for (const bool segments : {false, true}) {
      for (const float offset : {0.0f, 60.0f, 4000.0f}) {
        for (int packet = 0; packet < 8; ++packet) {
          Packet pk;
          // Some segment packets start within a radius of the apex (tilted sides).
          make_packet(offset, segments, packet % 4 == 0, g, pk, segments && packet % 2 == 1 ? 0.2f : 0.0f);
          rt::GroupFrusta<64> frusta, own;
          build_frusta(pk, segments, slabs, true, frusta);
          build_frusta(pk, segments, slabs, false, own);
          const rt::GroupFrusta<64>& expected = slabs ? frusta : own;
          for (int batch = 0; batch < 60; ++batch) {
            rt::TriangleLanes8 t;
            const int n = 1 + static_cast<int>(g() % 8);
            for (int i = 0; i < 8; ++i) {
              // Lanes past n hold stale triangles, as a leaf's last batch does.
              const std::array<Vec3, 3> tri = triangle_near(pk, segments, g);
              for (int k = 0; k < 3; ++k) {
                t.p[k][0][i] = tri[static_cast<std::size_t>(k)].x;
                t.p[k][1][i] = tri[static_cast<std::size_t>(k)].y;
                t.p[k][2][i] = tri[static_cast<std::size_t>(k)].z;
              }
            }
            const std::uint32_t lanes = ((1u << n) - 1u) & (batch % 3 == 0 ? g() | 1u : ~0u);
            const std::uint64_t groups = batch % 2 == 0 ? ~std::uint64_t{0} : (std::uint64_t{g()} << 32 | g());
            std::uint64_t out[8];
            frusta.reached8(t, lanes, groups, out);
            for (int i = 0; i < 8; ++i) {
              const std::uint64_t want =
                  (lanes >> i & 1u) ? expected.reached(t.corner(0, i), t.corner(1, i), t.corner(2, i), groups) : 0u;
              ASSERT_EQ(out[i], want) << "triangle " << i << " of batch " << batch << " packet " << packet
                                      << " offset " << offset << (segments ? " segments" : " rays")
                                      << (slabs ? " slabs" : " own frusta");
              if (!(lanes >> i & 1u)) continue;
              ++compared;
              if (want == 0) ++culled;
              if (want != 0 && (want & groups) != groups) ++some_groups;
            }
          }
        }
      }
    }
  }
  // The comparison has teeth: triangles culled outright and reaching some groups.
  EXPECT_GT(culled, compared / 10) << culled << " of " << compared;
  EXPECT_GT(some_groups, compared / 10) << some_groups << " of " << compared;
}

TEST(GroupFrusta, TrianglesBeyondTheRaysEndsAreCulledByTheFarPlane) {
  // Rays from the light to points 10 to 12 along +z.
  const Vec3 light(3.0f, -2.0f, 1.0f);
  float q[3][8] = {};
  alignas(32) float reach[8];
  for (int lane = 0; lane < 8; ++lane) {
    q[0][lane] = 0.001f * static_cast<float>(lane % 4);
    q[1][lane] = 0.001f * static_cast<float>(lane / 4);
    q[2][lane] = 1.0f;
    reach[lane] = 10.0f + 0.25f * static_cast<float>(lane);
  }
  rt::GroupFrusta<8> with_far, without;
  with_far.reset(light, 1);
  with_far.set_group(0, q, 0xFFu, reach);
  without.reset(light, 1);
  without.set_group(0, q, 0xFFu);
  const auto at_depth = [&](float z, int corner) {
    return light + Vec3(corner == 1 ? 0.05f : -0.05f, corner == 2 ? 0.05f : -0.05f, z);
  };
  // Across the rays just behind the farthest end: only the far plane culls it.
  EXPECT_EQ(with_far.reached(at_depth(12.1f, 0), at_depth(12.1f, 1), at_depth(12.3f, 2), 1u), 0u);
  EXPECT_EQ(without.reached(at_depth(12.1f, 0), at_depth(12.1f, 1), at_depth(12.3f, 2), 1u), 1u);
  // Between the light and the ends, or straddling the farthest one: reached.
  EXPECT_EQ(with_far.reached(at_depth(5.0f, 0), at_depth(5.0f, 1), at_depth(5.0f, 2), 1u), 1u);
  EXPECT_EQ(with_far.reached(at_depth(11.5f, 0), at_depth(12.5f, 1), at_depth(12.5f, 2), 1u), 1u);
  // Boxes the same: one just behind the farthest end is culled by the far
  // plane only; one straddling the ends (10 to 11.75) is reached.
  const auto across = [&](float z0, float z1) {
    return Aabb{light + Vec3(-0.05f, -0.05f, z0), light + Vec3(0.05f, 0.05f, z1)};
  };
  EXPECT_EQ(with_far.box_reached(across(12.1f, 12.4f), 1u), 0u);
  EXPECT_EQ(without.box_reached(across(12.1f, 12.4f), 1u), 1u);
  EXPECT_EQ(with_far.box_reached(across(11.5f, 12.4f), 1u), 1u);
  EXPECT_EQ(with_far.box_reached(across(2.0f, 3.0f), 1u), 1u);
}

TEST(GroupFrusta, GroupsWithoutAFrustumReachEverything) {
  const Vec3 apex(1.0f, 2.0f, 3.0f);
  rt::GroupFrusta<16> frusta;
  frusta.reset(apex, 11);
  float wide[3][8] = {{1, -1, 0, 0, 1, 0, 0, 1}, {0, 0, 1, -1, 1, 0, 1, 1}, {0, 0, 0, 0, 0, 1, 1, 1}};
  frusta.set_group(3, wide, 0xFFu);  // spreads over more than 75 degrees
  float narrow[3][8] = {};
  for (int lane = 0; lane < 8; ++lane) narrow[2][lane] = 1.0f;
  frusta.set_group(9, narrow, 0xFFu);
  frusta.set_group(10, narrow, 0u);  // no lanes: nothing to bound
  // Beside every group's rays (they run along +z from the apex).
  const Vec3 p0 = apex + Vec3(5, 5, 1), p1 = apex + Vec3(6, 5, 1), p2 = apex + Vec3(5, 6, 1);
  const std::uint32_t all = (1u << 11) - 1u;
  EXPECT_EQ(frusta.reached(p0, p1, p2, all), all & ~(1u << 9));
  // A triangle around the narrow group's rays is reached by it too.
  EXPECT_EQ(frusta.reached(apex + Vec3(-1, -1, 2), apex + Vec3(1, -1, 2), apex + Vec3(0, 1, 2), all), all);
  // Corners that are not finite are never culled.
  const Vec3 bad(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  EXPECT_EQ(frusta.reached(bad, p1, p2, 1u << 9), 1u << 9);
  EXPECT_EQ(frusta.reached(Vec3(kInf, 0, 0), p1, p2, 1u << 9), 1u << 9);
  // Boxes likewise: beside the rays only the narrow group culls one; a box
  // that is empty or not finite is reached by every group.
  EXPECT_EQ(frusta.box_reached({apex + Vec3(5, 5, 1), apex + Vec3(6, 6, 2)}, all), all & ~(1u << 9));
  EXPECT_EQ(frusta.box_reached(Aabb{}, 1u << 9), 1u << 9);
  EXPECT_EQ(frusta.box_reached({bad, p1}, 1u << 9), 1u << 9);
  EXPECT_EQ(frusta.box_reached({Vec3(-kInf), Vec3(kInf)}, 1u << 9), 1u << 9);
}

}  // namespace
}  // namespace sinew
