// The stochastic rays (render/stages/tile_stages.h place_light_samples,
// place_ao_rays; render/sampling/sample_pattern.h): every area-light sample
// and ambient occlusion ray answers as brute-force any-hit over every
// triangle does, for sphere, rectangle and sun lights, both triangle tests
// and every packet width, with one mannequin inside its pose space and one
// outside it (the fallback); the rays start and end where the pattern and
// the light's shape say; the pattern is stratified and a function of the
// pixel alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/sampling/sample_pattern.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/scene/scene.h"
#include "tests/raytrace/render_test_support.h"
#include "tests/support/brute_force.h"
#include "runtime/jobs/job_system.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::scene;

struct RayKind {
  const char* name;
  rt::Light light;  // unused for ambient occlusion
  bool ambient_occlusion = false;
  int disk_steps = rt::RenderSettings{}.sphere_disk_steps;  // a sphere light's (RenderSettings::sphere_disk_steps)
};

std::vector<RayKind> ray_kinds() {
  std::vector<RayKind> kinds;
  rt::Light sphere;
  sphere.position = Vec3(1.5f, 3.0f, 2.0f);
  sphere.radius = 0.6f;
  kinds.push_back({"sphere", sphere});
  // Each hit's own facing disk (RenderSettings::sphere_disk_steps 0): the
  // samples of a class leave many points near one another, and packets
  // cull them from an apex with a radius or clip lanes.
  kinds.push_back({"sphere facing each hit", sphere, false, 0});
  // A small one: its samples start close together beside their lengths,
  // so packets cull them with frusta from the light (traverse/segment_apex.h,
  // find_segment_apex).
  rt::Light small = sphere;
  small.radius = 0.08f;
  kinds.push_back({"small sphere", small});
  rt::Light rect;
  rect.kind = rt::Light::Kind::kRect;
  rect.position = Vec3(-1.0f, 2.5f, 1.5f);
  rect.edge_u = Vec3(1.2f, 0.0f, 0.0f);
  rect.edge_v = Vec3(0.0f, 0.3f, 0.9f);
  kinds.push_back({"rect", rect});
  rt::Light sun;
  sun.kind = rt::Light::Kind::kDirectional;
  sun.direction = Vec3(0.5f, 1.0f, 0.4f);
  sun.angular_radius = 0.15f;
  kinds.push_back({"sun", sun});
  kinds.push_back({"ao", rt::Light{}, true});
  return kinds;
}

// Round j of n of the kind's rays, placed on bit 0 (ambient occlusion
// rays `ao_radius` long).
void place_round(const RayKind& kind, float ao_radius, int j, int n, rt::TileScratch& s) {
  if (kind.ambient_occlusion) {
    rt::place_ao_rays(ao_radius, 0, j, n, s);
  } else {
    rt::place_light_samples(kind.light, kind.disk_steps, 0, j, n, s);
  }
}

// Every tile of a 48x48 image of the test scene: rounds of each ray kind,
// traced by the renderer's stage, each ray's answer checked against
// brute force.
TEST(SampleRays, EveryAreaLightAndAmbientOcclusionRayAnswersAsBruteForce) {
  const rt::Scene& sc = scene();
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.6f, 1.3f, 2.6f), Vec3(0.0f, 0.8f, 0.0f), Vec3(0, 1, 0), 50.0f}, 48, 48)
          .value();
  constexpr int kSamples = 3;
  constexpr float kAoRadius = 0.5f;
  for (const RayKind& kind : ray_kinds()) {
    for (const TriangleTest test : testing_support::kTests) {
      for (const int packet_rays : {1, 8, 256}) {
        SCOPED_TRACE(std::string(kind.name) + " packet " + std::to_string(packet_rays) + " test " +
                     std::to_string(static_cast<int>(test)));
        std::size_t rays = 0, blocked = 0, facing_away = 0, runs = 0, mixed_runs = 0;
        for (int ty = 0; ty < 48; ty += 16) {
          for (int tx = 0; tx < 48; tx += 16) {
            rt::TileScratch s;
            rt::TracePlan plan;
            plan.packet_rays = packet_rays;
            plan.region_blocks_x = packet_rays == 256 ? 4 : 1;
            plan.region_blocks_y = packet_rays == 256 ? 8 : 1;
            s.prepare(Tile{tx, ty, tx + 16, ty + 16, 0}, plan);
            rt::generate_camera_rays(camera, s);
            rt::TraversalCounters counters;
            rt::trace_primary(sc, camera, test, s, counters);
            rt::reconstruct_surfaces(sc, {Vec3(0.7f), camera.pixel_spread()}, s);
            rt::shift_pixels(7u, kind.ambient_occlusion ? rt::kAmbientOcclusionStream : 0u, s);
            for (int j = 0; j < kSamples; ++j) {
              std::fill(s.lit.begin(), s.lit.end(), std::uint8_t{0});
              rt::set_lit_bit(0, s);
              place_round(kind, kAoRadius, j, kSamples, s);
              rt::trace_shadow_rays(sc, test, 0, s, counters);
              // A tile whose rays reach no object traces none; its rays,
              // compacted here, must all be open.
              rt::compact_shadow_rays(s);
              // Each run (a packet) holds one sample class: its rays took
              // the same sample; an area light's run, one point of it.
              for (std::size_t r = 0; r + 1 < s.shadow_region_begin.size(); ++r) {
                const std::size_t i0 = s.shadow_region_begin[r], i1 = s.shadow_region_begin[r + 1];
                ASSERT_LT(i0, i1);
                const std::size_t k0 = s.shadow_pixel[i0];
                bool one_origin = true;
                for (std::size_t i = i0; i < i1; ++i) {
                  const std::size_t k = s.shadow_pixel[i];
                  ASSERT_EQ(rt::sample_class(s.pixel_x(k), s.pixel_y(k)), rt::sample_class(s.pixel_x(k0), s.pixel_y(k0)));
                  one_origin = one_origin && s.so_x[i] == s.so_x[i0] && s.so_y[i] == s.so_y[i0] && s.so_z[i] == s.so_z[i0];
                }
                ++runs;
                mixed_runs += one_origin ? 0 : 1;
              }
              std::vector<bool> has_ray(s.lanes, false);
              for (std::size_t i = 0; i < s.shadow_count; ++i) {
                const std::size_t k = s.shadow_pixel[i];
                ASSERT_FALSE(has_ray[k]) << "one ray per hit and round";
                has_ray[k] = true;
                const Ray ray = s.shadow_ray(i);
                const bool reference = testing_support::any_hit(soup, ray, test);
                ASSERT_EQ((s.lit[k] & 1u) == 0, reference)
                    << "pixel " << s.pixel_x(k) << "," << s.pixel_y(k) << " round " << j;
                ++rays;
                blocked += reference ? 1 : 0;
              }
              for (std::size_t k = 0; k < s.lanes; ++k) {
                if (!s.hit(k) || has_ray[k]) continue;
                // No ray: the sample lies behind the surface, so it is dark.
                ASSERT_EQ(s.lit[k] & 1u, 0u) << "pixel " << s.pixel_x(k) << "," << s.pixel_y(k);
                ++facing_away;
              }
            }
          }
        }
        // The scene gives every kind open and blocked rays.
        EXPECT_GT(rays, 1000u);
        EXPECT_GT(blocked, 20u);
        EXPECT_LT(blocked, rays);
        if (kind.ambient_occlusion) {
          EXPECT_EQ(facing_away, 0u);
        }
        if (packet_rays > 1 && kind.light.kind == rt::Light::Kind::kRect) {
          EXPECT_EQ(mixed_runs, 0u) << "a class's samples of a rectangle leave one point";
        }
        if (packet_rays > 1 && kind.light.kind == rt::Light::Kind::kPoint && !kind.ambient_occlusion &&
            kind.disk_steps > 0) {
          // Most runs leave one point of the sphere (the hits of one cell
          // of the snapped axes share a disk); this light is close enough
          // that some tiles' hits turn it more ways than a class makes runs
          // for, so both kinds of packet are traced here.
          EXPECT_LT(mixed_runs * 10, runs);
          EXPECT_GT(mixed_runs, 0u);
        }
      }
    }
  }
}

// Where each kind's rays run: a sphere light's from points of its disk
// facing the hit to the hit, a rectangle's from points on it, the sun's
// within its angular radius, ambient occlusion's within the radius, about
// the normal.
TEST(SampleRays, RaysRunBetweenTheHitAndThePointsTheShapeAllows) {
  const rt::Scene& sc = scene();
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.6f, 1.3f, 2.6f), Vec3(0.0f, 0.8f, 0.0f), Vec3(0, 1, 0), 50.0f}, 32, 32)
          .value();
  std::vector<RayKind> kinds = ray_kinds();
  // A sphere light's disk at the extremes of its steps: each hit's own
  // facing disk (0), the coarsest and the finest grids.
  for (const int steps : {0, rt::kMinSphereDiskSteps, rt::kMaxSphereDiskSteps}) {
    RayKind sphere = kinds.front();
    sphere.disk_steps = steps;
    kinds.push_back(sphere);
  }
  for (const RayKind& kind : kinds) {
    SCOPED_TRACE(std::string(kind.name) + " steps " + std::to_string(kind.disk_steps));
    rt::TileScratch s;
    s.prepare(Tile{0, 0, 32, 32, 0}, rt::TracePlan{});
    rt::generate_camera_rays(camera, s);
    rt::TraversalCounters counters;
    rt::trace_primary(sc, camera, TriangleTest::kFast, s, counters);
    rt::reconstruct_surfaces(sc, {Vec3(0.7f), camera.pixel_spread()}, s);
    rt::shift_pixels(1u, 3u, s);
    const rt::Light& light = kind.light;
    std::size_t checked = 0;
    for (int j = 0; j < 4; ++j) {
      rt::set_lit_bit(0, s);
      place_round(kind, 0.5f, j, 4, s);
      rt::compact_shadow_rays(s);
      for (std::size_t i = 0; i < s.shadow_count; ++i) {
        const std::size_t k = s.shadow_pixel[i];
        const Vec3 hit(s.px[k], s.py[k], s.pz[k]);
        const Vec3 normal(s.gx[k], s.gy[k], s.gz[k]);
        const Ray ray = s.shadow_ray(i);
        const float scale = 1e-4f * (1.0f + glm::length(hit) + glm::length(light.position));
        if (kind.ambient_occlusion) {
          ASSERT_LT(glm::length(ray.origin - hit), scale);
          ASSERT_EQ(ray.t_max, 1.0f);
          ASSERT_LE(glm::length(ray.direction), 0.5f * (1.0f + 1e-5f));
          ASSERT_GT(glm::dot(ray.direction, normal), 0.0f);
          ++checked;
          continue;
        }
        if (light.kind == rt::Light::Kind::kDirectional) {
          const Vec3 axis = glm::normalize(light.direction);
          const float angle = std::acos(std::min(1.0f, glm::dot(glm::normalize(ray.direction), axis)));
          ASSERT_LE(angle, light.angular_radius * (1.0f + 1e-4f) + 1e-5f);
          ASSERT_LT(glm::length(ray.origin - hit), scale);
          ASSERT_TRUE(std::isinf(ray.t_max));
          ++checked;
          continue;
        }
        // From a point on the light to the hit, t in [0, 1).
        ASSERT_EQ(ray.t_max, 1.0f);
        ASSERT_LT(glm::length(ray.origin + ray.direction - hit), scale);
        const Vec3 from = ray.origin - light.position;
        if (light.kind == rt::Light::Kind::kPoint) {
          ASSERT_LE(glm::length(from), light.radius * (1.0f + 1e-5f));
          // On a disk through the centre whose axis is the direction to
          // the hit snapped to the octahedral grid: within 122 / steps
          // degrees (29.3 at 4, 7.6 at 16); without steps, facing it.
          const Vec3 axis = glm::normalize(light.position - hit);
          const float tilt = kind.disk_steps == 0 ? 0.0f : 122.0f / static_cast<float>(kind.disk_steps);
          ASSERT_LE(std::fabs(glm::dot(from, axis)), glm::length(from) * std::sin(tilt * 3.14159265f / 180.0f) + 1e-5f)
              << "on a disk nearly facing the hit";
        } else {
          const float a = glm::dot(from, light.edge_u) / glm::dot(light.edge_u, light.edge_u);
          const float b = glm::dot(from, light.edge_v) / glm::dot(light.edge_v, light.edge_v);
          ASSERT_LE(std::fabs(a), 0.5f + 1e-5f);
          ASSERT_LE(std::fabs(b), 0.5f + 1e-5f);
        }
        ++checked;
      }
    }
    EXPECT_GT(checked, 500u);
  }
}

// A floor of 32x32 quads (a kd-tree of its own, y = 0) reaching far beyond
// the lights, as a game's does, and a box mesh far off, so that the top
// level holds two objects.
std::unique_ptr<rt::Scene> tiled_floor_scene() {
  auto sc = std::make_unique<rt::Scene>();
  rt::StaticMeshDesc floor;
  constexpr int kQuads = 32;
  for (int j = 0; j <= kQuads; ++j) {
    for (int i = 0; i <= kQuads; ++i) {
      floor.positions.emplace_back(-40.0f + 2.5f * static_cast<float>(i), 0.0f, -40.0f + 2.5f * static_cast<float>(j));
    }
  }
  for (std::uint32_t j = 0; j < kQuads; ++j) {
    for (std::uint32_t i = 0; i < kQuads; ++i) {
      const std::uint32_t a = j * (kQuads + 1) + i, b = a + 1, c = a + kQuads + 1, d = c + 1;
      floor.triangles.push_back({a, c, b});
      floor.triangles.push_back({b, c, d});
    }
  }
  EXPECT_TRUE(sc->add_static_mesh(floor).ok());
  rt::StaticMeshDesc box;
  box.positions = {{6, 0, 6}, {7, 0, 6}, {6, 0, 7}, {7, 0, 7}, {6, 1, 6}, {7, 1, 6}, {6, 1, 7}, {7, 1, 7}};
  box.triangles = {{4, 6, 5}, {5, 6, 7}, {0, 4, 1}, {1, 4, 5}, {0, 2, 4}, {2, 6, 4},
                   {1, 5, 3}, {3, 5, 7}, {2, 3, 6}, {3, 7, 6}};
  EXPECT_TRUE(sc->add_static_mesh(box).ok());
  JobSystem jobs(1);
  EXPECT_TRUE(sc->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return sc;
}

// Segment rays leave their surface clear of the traversal's slack
// (render/stages/stage_support.h slack_clearance): those from a flat floor,
// in the open, enter no object, not even the floor's, and all answer open
// as brute force does. The same rays without the clearance enter the floor.
TEST(SampleRays, RaysLeavingAFlatFloorEnterNoObject) {
  const std::unique_ptr<rt::Scene> sc = tiled_floor_scene();
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(*sc);
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.0f, 3.0f, 2.0f), Vec3(0.0f, 0.0f, 0.0f), Vec3(0, 1, 0), 50.0f}, 32, 32)
          .value();
  std::vector<RayKind> kinds = ray_kinds();
  // The lights above the floor's middle, away from the box.
  for (RayKind& kind : kinds) kind.light.position = Vec3(0.5f, 3.0f, -0.5f);
  for (const RayKind& kind : kinds) {
    for (const TriangleTest test : testing_support::kTests) {
      for (const bool clear : {true, false}) {
        SCOPED_TRACE(std::string(kind.name) + (clear ? "" : " without the clearance") + " test " +
                     std::to_string(static_cast<int>(test)));
        rt::TileScratch s;
        rt::TracePlan plan;
        plan.packet_rays = 256;
        plan.region_blocks_x = 4;
        plan.region_blocks_y = 8;
        s.prepare(Tile{0, 0, 32, 32, 0}, plan);
        rt::generate_camera_rays(camera, s);
        rt::TraversalCounters counters;
        rt::trace_primary(*sc, camera, test, s, counters);
        rt::reconstruct_surfaces(*sc, {Vec3(0.7f), camera.pixel_spread()}, s);
        ASSERT_EQ(s.scene_magnitude, 40.0f);
        if (!clear) s.scene_magnitude = 0.0f;
        rt::shift_pixels(5u, kind.ambient_occlusion ? rt::kAmbientOcclusionStream : 0u, s);
        rt::TraversalCounters work;
        std::size_t rays = 0;
        for (int j = 0; j < 2; ++j) {
          rt::set_lit_bit(0, s);
          place_round(kind, 0.5f, j, 2, s);
          rt::trace_shadow_rays(*sc, test, 0, s, work);
          rt::compact_shadow_rays(s);
          for (std::size_t i = 0; i < s.shadow_count; ++i) {
            const std::size_t k = s.shadow_pixel[i];
            ASSERT_FALSE(testing_support::any_hit(soup, s.shadow_ray(i), test));
            ASSERT_NE(s.lit[k] & 1u, 0u) << "pixel " << s.pixel_x(k) << "," << s.pixel_y(k);
            ++rays;
          }
        }
        EXPECT_GT(rays, 1500u);
        if (clear) {
          EXPECT_EQ(work.object_visits, 0u);
          EXPECT_EQ(work.triangle_tests, 0u);
        } else {
          EXPECT_GT(work.object_visits, 0u);
        }
      }
    }
  }
}

TEST(SamplePattern, EachPixelsSamplesFillEveryStratumOnceAndSpreadOverTheOtherAxis) {
  for (const int n : {1, 4, 16, 64}) {
    for (int y = 0; y < 8; ++y) {
      for (int x = 0; x < 8; ++x) {
        const rt::PixelShift shift = rt::pixel_shift(5u, 2u, x, y);
        std::set<int> strata;
        std::vector<float> vs;
        for (int j = 0; j < n; ++j) {
          const Vec2 p = rt::square_sample(shift, j, n);
          ASSERT_GE(p.x, 0.0f);
          ASSERT_LT(p.x, 1.0f);
          ASSERT_GE(p.y, 0.0f);
          ASSERT_LT(p.y, 1.0f);
          strata.insert(static_cast<int>(p.x * static_cast<float>(n)));
          vs.push_back(p.y);
          const Vec2 d = rt::disk_sample(shift, j, n);
          ASSERT_LE(glm::length(d), 1.0f + 1e-6f);
          // The disk point is the square point in polar form.
          ASSERT_NEAR(glm::length(d), std::sqrt(p.x), 1e-5f);
          const float angle = std::atan2(d.y, d.x) / (2.0f * 3.14159265f);
          const float turns = angle < 0.0f ? angle + 1.0f : angle;
          const float gap = std::fabs(turns - p.y);
          ASSERT_LT(std::min(gap, 1.0f - gap), 1e-4f);
        }
        ASSERT_EQ(strata.size(), static_cast<std::size_t>(n));
        // The golden-ratio lattice leaves no gap in v wider than 3/n.
        std::sort(vs.begin(), vs.end());
        float widest = vs.front() + 1.0f - vs.back();
        for (std::size_t i = 1; i < vs.size(); ++i) widest = std::max(widest, vs[i] - vs[i - 1]);
        ASSERT_LE(widest, n == 1 ? 1.0f : 3.0f / static_cast<float>(n));
      }
    }
  }
}

TEST(SamplePattern, ShiftsDependOnSeedStreamAndPixelOnly) {
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      const rt::PixelShift a = rt::pixel_shift(9u, 1u, x, y);
      const rt::PixelShift b = rt::pixel_shift(9u, 1u, x, y);
      ASSERT_EQ(a.xi, b.xi);
      ASSERT_EQ(a.eta, b.eta);
      ASSERT_NEAR(a.cos_eta, std::cos(2.0f * 3.14159265f * a.eta), 1e-5f);
      ASSERT_NEAR(a.sin_eta, std::sin(2.0f * 3.14159265f * a.eta), 1e-5f);
      EXPECT_NE(rt::pixel_shift(10u, 1u, x, y).xi, a.xi);
      EXPECT_NE(rt::pixel_shift(9u, 2u, x, y).xi, a.xi);
    }
  }
}

// The interleaving: every 2x2 block holds the four classes, their shifts
// one per quadrant of (xi, eta); the block repeats, so pixels two apart
// share their shift (and take the same sample each round); and no two
// neighbours share a class.
TEST(SamplePattern, EveryTwoByTwoBlockHoldsFourStratifiedShifts) {
  for (const std::uint32_t stream : {0u, 3u, rt::kAmbientOcclusionStream}) {
    for (int by = 0; by < 12; by += 2) {
      for (int bx = 0; bx < 12; bx += 2) {
        std::set<int> classes, xi_quarters;
        std::set<float> etas;
        for (int y = by; y < by + 2; ++y) {
          for (int x = bx; x < bx + 2; ++x) {
            const rt::PixelShift a = rt::pixel_shift(7u, stream, x, y);
            classes.insert(rt::sample_class(x, y));
            xi_quarters.insert(static_cast<int>(a.xi * 4.0f));
            etas.insert(a.eta);
            const rt::PixelShift repeat = rt::pixel_shift(7u, stream, x + 2, y + 6);
            ASSERT_EQ(repeat.xi, a.xi);
            ASSERT_EQ(repeat.eta, a.eta);
            ASSERT_NE(rt::sample_class(x + 1, y), rt::sample_class(x, y));
            ASSERT_NE(rt::sample_class(x, y + 1), rt::sample_class(x, y));
            ASSERT_NE(rt::sample_class(x + 1, y + 1), rt::sample_class(x, y));
          }
        }
        EXPECT_EQ(classes.size(), 4u);
        EXPECT_EQ(xi_quarters.size(), 4u);
        // One eta per quarter turn: the four are a quarter apart.
        ASSERT_EQ(etas.size(), 4u);
        std::vector<float> sorted(etas.begin(), etas.end());
        for (std::size_t i = 1; i < sorted.size(); ++i) EXPECT_NEAR(sorted[i] - sorted[i - 1], 0.25f, 1e-6f);
      }
    }
  }
}

}  // namespace
}  // namespace sinew
