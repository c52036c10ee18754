// Packets of rays against single rays (traverse/packet_traversal.h,
// traverse/large_packet.h): 8-ray packets culled by a bound over their rays
// find the single-ray hits and occlusion; large packets of 1 to 64 groups
// find every lane's nearest hit and occlusion, given the tile's cull or
// every object, with and without lanes clipped to leaf boxes, and shadow
// rays to a point light do with group frusta and with slabs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "raytrace/accel/top_level.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/large_packet.h"
#include "raytrace/traverse/packet_traversal.h"
#include "raytrace/traverse/traversal.h"
#include "tests/raytrace/render_test_support.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::kInf;
using testing_support::kTests;
using testing_support::scene;
using testing_support::unit;

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
// goes through the escaped triangles' tree, the ground through the
// small-static tests).
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

}  // namespace
}  // namespace sinew
