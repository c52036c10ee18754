// Packet traversal (traverse/packet_traversal.h): every lane of an 8-ray
// packet gets the single-ray answer (the same t, u and v bits; the same
// triangle and instance, the mannequin's scenes having no exact ties; the
// same occlusion), for coherent camera packets, incoherent random packets
// with partial masks and finite t_max, shadow packets, and with the fallback
// for escaped triangles in use.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "animation/pose_space.h"
#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "raytrace/camera/camera.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/packet_traversal.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

using rt::kPacketSize;
using rt::RayPacket;
using rt::TriangleTest;
using testing_support::SoupTriangle;

constexpr TriangleTest kTests[] = {TriangleTest::kFast, TriangleTest::kWatertight};

// 24 random bits to [0, 1): our own conversion, so the stream is the same everywhere.
float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }

using Mannequin = testing_support::BakedModel;
using testing_support::idle_mannequin;


std::vector<Affine3> pose(const character::Model& model, const std::string& clip, double t,
                          const Affine3& instance = Affine3::identity()) {
  return testing_support::clip_pose(model, clip, t, instance);
}

// Two mannequins side by side on a ground quad; the second one idles or,
// with `kick`, kicks out of the pose space so the fallback carries escapes.
struct TestScene {
  rt::Scene scene;
  rt::FrameStats stats;
};

std::unique_ptr<TestScene> make_scene(bool kick, rt::BoneTreeKind trees = rt::BoneTreeKind::kKdTree) {
  const Mannequin& m = idle_mannequin(trees);
  auto out = std::make_unique<TestScene>();
  rt::Scene& scene = out->scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t instance = scene.add_instance(character).value();
    const Affine3 place = Affine3::translation(Vec3(0.9f * static_cast<float>(i) - 0.45f, 0.0f, 0.0f));
    const bool kicking = kick && i == 1;
    EXPECT_TRUE(scene.set_bones(instance, pose(m.model, kicking ? "kick" : "idle", kicking ? 0.4 : 0.7 * i, place))
                    .ok());
  }
  rt::StaticMeshDesc ground;
  ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  EXPECT_TRUE(scene.add_static_mesh(ground).ok());
  JobSystem jobs(2);
  auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
  EXPECT_TRUE(stats.ok()) << stats.status().message();
  if (stats.ok()) out->stats = *stats;
  return out;
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

bool identical(const Hit& a, const Hit& b) {
  return a.triangle_id == b.triangle_id && a.instance_id == b.instance_id && same_bits(a.t, b.t) &&
         same_bits(a.u, b.u) && same_bits(a.v, b.v);
}

std::string describe(const Ray& r, const Hit& packet, const Hit& single) {
  char text[320];
  std::snprintf(text, sizeof text,
                "ray o(%.9g,%.9g,%.9g) d(%.9g,%.9g,%.9g) t[%.9g,%.9g): packet t=%.9g tri %u inst %u, single t=%.9g "
                "tri %u inst %u",
                static_cast<double>(r.origin.x), static_cast<double>(r.origin.y), static_cast<double>(r.origin.z),
                static_cast<double>(r.direction.x), static_cast<double>(r.direction.y),
                static_cast<double>(r.direction.z), static_cast<double>(r.t_min), static_cast<double>(r.t_max),
                static_cast<double>(packet.t), packet.triangle_id, packet.instance_id, static_cast<double>(single.t),
                single.triangle_id, single.instance_id);
  return text;
}

struct Tally {
  std::size_t lanes = 0;
  std::size_t hits = 0;
  std::size_t wrong = 0;
  std::string first;
  void fail(const std::string& what) {
    if (wrong++ == 0) first = what;
  }
};

// Every lane of `packet` against the single-ray queries: nearest hits
// bit-identical, occlusion bits equal; inactive lanes stay misses.
void check_packet(const rt::Scene& scene, const RayPacket& packet, TriangleTest test, Tally& tally) {
  Hit hits[kPacketSize];
  rt::intersect_packet(scene, packet, test, hits);
  const std::uint8_t occluded = rt::occluded_packet(scene, packet, test);
  for (int lane = 0; lane < kPacketSize; ++lane) {
    const Ray ray = packet.ray(lane);
    if (!(packet.active >> lane & 1u)) {
      if (hits[lane].valid() || (occluded >> lane & 1u)) tally.fail("inactive lane " + std::to_string(lane) + " hit");
      continue;
    }
    ++tally.lanes;
    const Hit single = rt::intersect(scene, ray, test);
    tally.hits += single.valid() ? 1 : 0;
    if (!identical(hits[lane], single)) tally.fail(describe(ray, hits[lane], single));
    if (((occluded >> lane & 1u) != 0) != rt::occluded(scene, ray, test)) {
      tally.fail("occlusion differs: " + describe(ray, hits[lane], single));
    }
  }
}

rt::PinholeCamera test_camera(int size) {
  return rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f}, size, size)
      .value();
}

// Camera packets over the whole image: 8x1 rows or 4x2 blocks.
Tally check_camera_packets(const rt::Scene& scene, int width, int height) {
  const rt::PinholeCamera camera = test_camera(64);
  Tally tally;
  for (const TriangleTest test : kTests) {
    for (int y = 0; y < 64; y += height) {
      for (int x = 0; x < 64; x += width) {
        RayPacket packet;
        for (int lane = 0; lane < kPacketSize; ++lane) packet.set(lane, camera.ray(x + lane % width, y + lane / width));
        check_packet(scene, packet, test, tally);
      }
    }
  }
  return tally;
}

// Random rays around the characters: random and axis-parallel directions,
// directions with zero components, rays aimed at triangle points; some
// lanes off, some with finite t_max or t_min > 0, a few invalid.
Tally check_random_packets(const rt::Scene& scene, std::size_t packets, std::uint32_t seed) {
  const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
  Aabb box;
  for (const rt::InstanceFrame& frame : scene.instances()) {
    for (const Vec3& p : frame.positions) box.extend(p);
  }
  const Vec3 c = box.center();
  const Vec3 e = box.extent();
  std::mt19937 g(seed);
  Tally tally;
  for (std::size_t p = 0; p < packets; ++p) {
    RayPacket packet;
    packet.active = static_cast<std::uint8_t>(p % 4 == 0 ? (g() & 0xFFu) : 0xFFu);
    // Half of the packets share an origin (coherent-ish), the others do not.
    const Vec3 shared = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * e * 1.6f;
    for (int lane = 0; lane < kPacketSize; ++lane) {
      Ray ray;
      ray.origin = (p % 2 == 0) ? shared : c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * e * 1.6f;
      const std::uint32_t kind = g() % 8;
      if (kind == 0) {
        ray.direction = Vec3(0.0f);
        ray.direction[static_cast<int>(g() % 3)] = (g() & 1u) ? 1.0f : -1.0f;
      } else if (kind <= 4) {
        const SoupTriangle& tri = soup[g() % soup.size()];
        const float u = unit(g);
        const float v = unit(g) * (1.0f - u);
        ray.direction = (1.0f - u - v) * tri.p0 + u * tri.p1 + v * tri.p2 - ray.origin;
      } else {
        ray.direction = Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f);
        if (kind == 5) ray.direction[static_cast<int>(g() % 3)] = 0.0f;
      }
      if (ray.direction == Vec3(0.0f) && g() % 4 != 0) ray.direction = Vec3(0.0f, -1.0f, 0.0f);
      if (g() % 3 == 0) ray.t_max = 0.2f + 1.5f * unit(g);  // in world units of a unit-ish direction
      if (g() % 5 == 0) ray.t_min = 0.3f * unit(g);
      packet.set(lane, ray);
    }
    for (const TriangleTest test : kTests) check_packet(scene, packet, test, tally);
  }
  return tally;
}

// Shadow packets: from each camera packet's hit points towards a point light.
struct ShadowTally {
  std::size_t lanes = 0;
  std::size_t occluded = 0;
  std::size_t wrong = 0;
};

ShadowTally check_shadow_packets(const rt::Scene& scene) {
  const rt::PinholeCamera camera = test_camera(64);
  const Vec3 light(1.5f, 3.0f, 2.0f);
  ShadowTally tally;
  for (const TriangleTest test : kTests) {
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; x += kPacketSize) {
        RayPacket shadow;
        shadow.active = 0;
        for (int lane = 0; lane < kPacketSize; ++lane) {
          const Ray primary = camera.ray(x + lane, y);
          const Hit hit = rt::intersect(scene, primary, test);
          Ray ray;
          if (hit.valid()) {
            ray.origin = primary.at(hit.t);
            ray.direction = light - ray.origin;
            ray.t_min = 1e-4f;
            ray.t_max = 1.0f;
            shadow.active = static_cast<std::uint8_t>(shadow.active | (1u << lane));
          }
          shadow.set(lane, ray);
        }
        const std::uint8_t bits = rt::occluded_packet(scene, shadow, test);
        for (int lane = 0; lane < kPacketSize; ++lane) {
          if (!(shadow.active >> lane & 1u)) {
            tally.wrong += (bits >> lane & 1u) ? 1 : 0;
            continue;
          }
          const bool single = rt::occluded(scene, shadow.ray(lane), test);
          ++tally.lanes;
          tally.occluded += single ? 1 : 0;
          tally.wrong += (((bits >> lane & 1u) != 0) != single) ? 1 : 0;
        }
      }
    }
  }
  return tally;
}

// The kick (or idle) pose, and the bone trees' kind. A packet's lanes need
// not meet the cells in their single rays' order, but they still find the
// same nearest hit (the same t, u and v; on an exact tie of t between two
// triangles the mannequin's scenes have none).
class PacketTraversal : public ::testing::TestWithParam<std::tuple<bool, rt::BoneTreeKind>> {
 protected:
  static bool kick() { return std::get<0>(GetParam()); }
  static std::unique_ptr<TestScene> scene() { return make_scene(kick(), std::get<1>(GetParam())); }
};

TEST_P(PacketTraversal, CoherentCameraPacketsMatchSingleRays) {
  const auto s = scene();
  for (const auto& [w, h] : {std::pair{8, 1}, std::pair{4, 2}}) {
    const Tally tally = check_camera_packets(s->scene, w, h);
    EXPECT_EQ(tally.wrong, 0u) << w << "x" << h << ", " << tally.lanes << " lanes; first: " << tally.first;
    EXPECT_EQ(tally.lanes, 2u * 64u * 64u);
    EXPECT_GT(tally.hits, tally.lanes / 4) << "the camera must see the characters and the ground";
  }
}

TEST_P(PacketTraversal, IncoherentRandomPacketsWithPartialMasksMatchSingleRays) {
  const auto s = scene();
  const Tally tally = check_random_packets(s->scene, 600, kick() ? 17u : 5u);
  EXPECT_EQ(tally.wrong, 0u) << tally.lanes << " lanes; first: " << tally.first;
  EXPECT_GT(tally.lanes, 2u * 600u * 6u);
  EXPECT_GT(tally.hits, tally.lanes / 4);
}

TEST_P(PacketTraversal, ShadowPacketsMatchSingleRays) {
  const auto s = scene();
  const ShadowTally tally = check_shadow_packets(s->scene);
  EXPECT_EQ(tally.wrong, 0u) << tally.lanes << " lanes";
  EXPECT_GT(tally.occluded, 100u) << "the characters shadow the ground";
  EXPECT_LT(tally.occluded, tally.lanes);
}

TEST_P(PacketTraversal, TheFallbackIsInUseOnlyForTheKick) {
  const auto s = scene();
  if (kick()) {
    EXPECT_GT(s->stats.escaped_triangles, 0u) << "a kick is not an idle pose";
  } else {
    EXPECT_EQ(s->stats.escaped_triangles, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Poses, PacketTraversal,
                         ::testing::Combine(::testing::Values(false, true),
                                            ::testing::Values(rt::BoneTreeKind::kKdTree, rt::BoneTreeKind::kBvh)),
                         [](const ::testing::TestParamInfo<std::tuple<bool, rt::BoneTreeKind>>& p) {
                           return std::string(std::get<0>(p.param) ? "KickWithFallback" : "Idle") +
                                  (std::get<1>(p.param) == rt::BoneTreeKind::kBvh ? "Bvh" : "KdTree");
                         });

// Lanes that share cells share node fetches: a coherent camera packet walks
// fewer nodes than its eight rays do one by one.
TEST(PacketTraversalCounters, CoherentPacketsShareNodeVisits) {
  const auto s = make_scene(false);
  const rt::PinholeCamera camera = test_camera(64);
  rt::TraversalCounters single, packet;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; x += kPacketSize) {
      RayPacket p;
      for (int lane = 0; lane < kPacketSize; ++lane) {
        p.set(lane, camera.ray(x + lane, y));
        rt::intersect(s->scene, camera.ray(x + lane, y), TriangleTest::kFast, &single);
      }
      Hit hits[kPacketSize];
      rt::intersect_packet(s->scene, p, TriangleTest::kFast, hits, &packet);
    }
  }
  EXPECT_EQ(packet.rays, single.rays);
  // Object visits and triangle tests count per lane, as the single rays
  // count them; the packet culls objects and leaves with its own bounds, so
  // it may enter a few fewer or more than its rays would one by one.
  EXPECT_GT(packet.object_visits, single.object_visits / 2);
  EXPECT_LT(packet.object_visits, single.object_visits * 2);
  EXPECT_LT(packet.node_visits, single.node_visits / 2);
  RecordProperty("single_node_visits", std::to_string(single.node_visits));
  RecordProperty("packet_node_visits", std::to_string(packet.node_visits));
  RecordProperty("single_triangle_tests", std::to_string(single.triangle_tests));
  RecordProperty("packet_triangle_tests", std::to_string(packet.triangle_tests));
}

// Not a test: rays per second on one thread, single rays against packets,
// primary and shadow rays of a 256x256 image of two mannequins, median of 5.
// Run with --gtest_also_run_disabled_tests --gtest_filter='*PacketSpeed*'.
TEST(PacketTraversalBench, DISABLED_PacketSpeed) {
  const auto s = make_scene(false);
  const rt::Scene& scene = s->scene;
  constexpr int kSize = 256;
  const rt::PinholeCamera camera = test_camera(kSize);
  const Vec3 light(1.5f, 3.0f, 2.0f);
  std::vector<Ray> primary, shadow;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) primary.push_back(camera.ray(x, y));
  }
  for (const Ray& r : primary) {
    const Hit hit = rt::intersect(scene, r, TriangleTest::kFast);
    Ray ray;
    ray.t_max = -1.0f;  // invalid: a miss pixel casts no shadow ray
    if (hit.valid()) {
      ray.origin = r.at(hit.t);
      ray.direction = light - ray.origin;
      ray.t_min = 1e-4f;
      ray.t_max = 1.0f;
    }
    shadow.push_back(ray);
  }
  // 4x2 pixel blocks for packets (the shadow rays keep the pixel order).
  const auto packet_at = [&](const std::vector<Ray>& rays, int bx, int by) {
    RayPacket p;
    p.active = 0;
    for (int lane = 0; lane < kPacketSize; ++lane) {
      const Ray& r = rays[static_cast<std::size_t>((by + lane / 4) * kSize + bx + lane % 4)];
      p.set(lane, r);
      if (r.t_min < r.t_max) p.active = static_cast<std::uint8_t>(p.active | (1u << lane));
    }
    return p;
  };
  // Single and packet runs alternate so both see the same machine load.
  const auto seconds_of = [](auto&& body) {
    const auto start = std::chrono::steady_clock::now();
    body();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const auto median_rates = [&](auto&& single_body, auto&& packet_body, std::size_t rays) {
    std::vector<double> single_rates, packet_rates;
    for (int run = 0; run < 5; ++run) {
      single_rates.push_back(static_cast<double>(rays) / seconds_of(single_body));
      packet_rates.push_back(static_cast<double>(rays) / seconds_of(packet_body));
    }
    std::sort(single_rates.begin(), single_rates.end());
    std::sort(packet_rates.begin(), packet_rates.end());
    return std::pair{single_rates[2], packet_rates[2]};
  };
  std::size_t shadow_rays = 0;
  for (const Ray& r : shadow) shadow_rays += r.t_min < r.t_max ? 1 : 0;
  for (const TriangleTest test : kTests) {
    std::uint64_t sink = 0;
    const auto [single_primary, packet_primary] = median_rates(
        [&] {
          for (const Ray& r : primary) sink += rt::intersect(scene, r, test).triangle_id;
        },
        [&] {
          Hit hits[kPacketSize];
          for (int by = 0; by < kSize; by += 2) {
            for (int bx = 0; bx < kSize; bx += 4) {
              rt::intersect_packet(scene, packet_at(primary, bx, by), test, hits);
              sink += hits[0].triangle_id;
            }
          }
        },
        primary.size());
    const auto [single_shadow, packet_shadow] = median_rates(
        [&] {
          for (const Ray& r : shadow) sink += rt::occluded(scene, r, test) ? 1 : 0;
        },
        [&] {
          for (int by = 0; by < kSize; by += 2) {
            for (int bx = 0; bx < kSize; bx += 4) sink += rt::occluded_packet(scene, packet_at(shadow, bx, by), test);
          }
        },
        shadow_rays);
    std::printf("%s: primary %.3f Mrays/s single, %.3f packet (x%.2f); shadow (%zu rays) %.3f single, %.3f packet "
                "(x%.2f)  [sink %llu]\n",
                test == TriangleTest::kFast ? "fast" : "watertight", single_primary * 1e-6, packet_primary * 1e-6,
                packet_primary / single_primary, shadow_rays, single_shadow * 1e-6, packet_shadow * 1e-6,
                packet_shadow / single_shadow, static_cast<unsigned long long>(sink));
  }
}

}  // namespace
}  // namespace sinew
