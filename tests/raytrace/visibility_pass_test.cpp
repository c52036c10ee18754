// Renderer::render_visibility, the light rays from a host's own surfaces:
// fed the surfaces Sinew's camera path computes (position, camera-facing
// geometric normal, rounding bound), its masks are the camera path's, bit
// for bit, for every kind of light and any thread count; on a host's ground that is not in the
// scene, every hard shadow ray answers as brute force over the scene's
// triangles and the soft masks are fractions of their samples; pixels
// without a surface get 1; bad inputs are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/render/surface.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/render/trace_plan.h"
#include "runtime/jobs/job_system.h"
#include "tests/raytrace/render_test_support.h"
#include "tests/support/brute_force.h"

namespace sinew {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The camera path's surfaces, per pixel: what reconstruct_surfaces leaves
// in the tile scratch; a NaN position where the camera ray missed.
struct Surfaces {
  int width = 0, height = 0;
  std::vector<Vec3> position, normal;
  std::vector<float> error;

  rt::HostSurfaces host() const {
    rt::HostSurfaces h;
    h.width = width;
    h.height = height;
    h.position = position;
    h.normal = normal;
    h.position_error = error;
    return h;
  }
};

Surfaces camera_surfaces(const rt::Scene& sc, const rt::PinholeCamera& camera) {
  Surfaces out;
  out.width = camera.width();
  out.height = camera.height();
  const std::size_t pixels = static_cast<std::size_t>(out.width * out.height);
  out.position.assign(pixels, Vec3(kNaN));
  out.normal.assign(pixels, Vec3(0.0f));
  out.error.assign(pixels, 0.0f);
  constexpr int kTile = 16;
  for (int ty = 0; ty < out.height; ty += kTile) {
    for (int tx = 0; tx < out.width; tx += kTile) {
      rt::TileScratch s;
      s.prepare(Tile{tx, ty, std::min(tx + kTile, out.width), std::min(ty + kTile, out.height), 0},
                rt::plan_for_packet_rays(8));
      rt::generate_camera_rays(camera, s);
      rt::TraversalCounters counters;
      rt::trace_primary(sc, camera, rt::TriangleTest::kFast, s, counters);
      rt::reconstruct_surfaces(sc, {Vec3(0.7f), camera.pixel_spread()}, s);
      for (std::size_t k = 0; k < s.lanes; ++k) {
        if (!s.is_pixel(k) || !s.hit(k)) continue;
        const std::size_t p = static_cast<std::size_t>(s.pixel_y(k) * out.width + s.pixel_x(k));
        out.position[p] = Vec3(s.px[k], s.py[k], s.pz[k]);
        out.normal[p] = Vec3(s.gx[k], s.gy[k], s.gz[k]);
        out.error[p] = s.error[k];
      }
    }
  }
  return out;
}

struct Masks {
  std::vector<float> shadow, ambient_occlusion;
};

rt::FrameBuffers mask_buffers(int width, int height, std::size_t lights, Masks& masks) {
  const std::size_t pixels = static_cast<std::size_t>(width * height);
  masks.shadow.assign(pixels * lights, -1.0f);
  masks.ambient_occlusion.assign(pixels, -1.0f);
  rt::FrameBuffers buffers;
  buffers.width = width;
  buffers.height = height;
  buffers.shadow = masks.shadow;
  buffers.ambient_occlusion = masks.ambient_occlusion;
  return buffers;
}

Masks host_masks(const rt::Scene& sc, const rt::HostSurfaces& surfaces, const rt::RenderSettings& settings,
                 std::size_t lights, int threads) {
  JobSystem jobs(threads);
  Masks masks;
  const rt::FrameBuffers buffers = mask_buffers(surfaces.width, surfaces.height, lights, masks);
  const auto stats = rt::Renderer().render_visibility(sc, surfaces, settings, buffers, jobs);
  EXPECT_TRUE(stats.ok()) << stats.status().message();
  return masks;
}

TEST(VisibilityPass, SinewsOwnSurfacesGiveTheCameraPathsMasks) {
  const rt::Scene& sc = testing_support::scene();
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.6f, 3.2f), Vec3(0.0f, 0.5f, 0.0f), Vec3(0, 1, 0), 55.0f}, 64, 48)
          .value();
  const Surfaces surfaces = camera_surfaces(sc, camera);
  rt::Light hard, sphere, rect, sun;
  hard.position = Vec3(2.0f, 4.0f, 3.0f);
  sphere.position = Vec3(1.0f, 2.5f, 1.5f);
  sphere.radius = 0.8f;
  rect.kind = rt::Light::Kind::kRect;
  rect.position = Vec3(-1.5f, 3.0f, 1.0f);
  rect.edge_u = Vec3(1.0f, 0.0f, 0.0f);
  rect.edge_v = Vec3(0.0f, 0.2f, 0.8f);
  sun.kind = rt::Light::Kind::kDirectional;
  sun.direction = Vec3(-0.3f, 1.0f, 0.4f);
  sun.angular_radius = 0.1f;
  const std::vector<rt::Light> lights = {hard, sphere, rect, sun};
  rt::RenderSettings settings;
  settings.lights = lights;
  settings.shadow_samples = 4;
  settings.ao_rays = 4;
  settings.ao_radius = 0.5f;

  JobSystem jobs(2);
  Masks reference;
  const rt::FrameBuffers buffers = mask_buffers(64, 48, lights.size(), reference);
  ASSERT_TRUE(rt::Renderer().render(sc, camera, settings, buffers, jobs).ok());
  std::set<float> values(reference.shadow.begin(), reference.shadow.end());
  values.insert(reference.ambient_occlusion.begin(), reference.ambient_occlusion.end());
  ASSERT_TRUE(values.count(0.0f) && values.count(0.5f) && values.count(1.0f)) << "shadow, penumbra and light";

  for (const int threads : {1, 2}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const Masks masks = host_masks(sc, surfaces.host(), settings, lights.size(), threads);
    EXPECT_EQ(masks.shadow, reference.shadow);
    EXPECT_EQ(masks.ambient_occlusion, reference.ambient_occlusion);
  }
}

// A host's ground under the mannequins, not in Sinew's scene: pixel (x, y)
// is the point (-2 + 4 (x + 1/2) / W, 0, -2 + 4 (y + 1/2) / H), normal up;
// column 0 has no position and row 0 no normal (no surface: masks 1).
struct HostGround {
  static constexpr int kWidth = 48, kHeight = 40;
  static constexpr std::size_t kPositionPitch = (kWidth + 3) * sizeof(Vec3);  // padded rows
  std::vector<Vec3> position, normal;

  HostGround()
      : position(static_cast<std::size_t>(kHeight) * kPositionPitch / sizeof(Vec3), Vec3(kNaN)),
        normal(static_cast<std::size_t>(kWidth * kHeight), Vec3(0.0f, 1.0f, 0.0f)) {
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 1; x < kWidth; ++x) position[static_cast<std::size_t>(y * (kWidth + 3) + x)] = at(x, y);
    }
    for (int x = 0; x < kWidth; ++x) normal[static_cast<std::size_t>(x)] = Vec3(0.0f);
  }
  static Vec3 at(int x, int y) {
    return {-2.0f + 4.0f * (static_cast<float>(x) + 0.5f) / kWidth, 0.0f,
            -2.0f + 4.0f * (static_cast<float>(y) + 0.5f) / kHeight};
  }
  static bool has_surface(int x, int y) { return x > 0 && y > 0; }
  rt::HostSurfaces host(float normal_offset) const {
    rt::HostSurfaces h;
    h.width = kWidth;
    h.height = kHeight;
    h.position = position;
    h.normal = normal;
    h.normal_offset = normal_offset;
    h.row_pitch.position = kPositionPitch;
    return h;
  }
};

TEST(VisibilityPass, HardShadowsOnAHostsGroundAnswerAsBruteForce) {
  const rt::Scene& sc = testing_support::mannequins_scene();
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  const HostGround ground;
  constexpr float kOffset = 1e-3f;
  rt::Light light;
  light.position = Vec3(1.0f, 2.5f, 1.5f);
  for (const rt::TriangleTest test : testing_support::kTests) {
    for (const int packet_rays : {1, 8, 256}) {
      SCOPED_TRACE("packet " + std::to_string(packet_rays) + " test " + std::to_string(static_cast<int>(test)));
      rt::RenderSettings settings;
      settings.light = light;
      settings.triangle_test = test;
      settings.packet_rays = packet_rays;
      const Masks masks = host_masks(sc, ground.host(kOffset), settings, 1, 2);
      std::size_t shadowed = 0;
      for (int y = 0; y < HostGround::kHeight; ++y) {
        for (int x = 0; x < HostGround::kWidth; ++x) {
          const float mask = masks.shadow[static_cast<std::size_t>(y * HostGround::kWidth + x)];
          if (!HostGround::has_surface(x, y)) {
            ASSERT_EQ(mask, 1.0f) << x << ", " << y;
            continue;
          }
          rt::SurfacePoint surface;
          surface.position = HostGround::at(x, y);
          surface.geometric_normal = Vec3(0.0f, 1.0f, 0.0f);
          surface.error = Vec3(kOffset);  // |n| sums to 1: the push is the offset
          const Ray ray = rt::shadow_ray_from_light(surface, light.position - surface.position, light.position);
          const bool blocked = testing_support::any_hit(soup, ray, test);
          ASSERT_EQ(mask, blocked ? 0.0f : 1.0f) << x << ", " << y;
          shadowed += blocked ? 1u : 0u;
        }
      }
      EXPECT_GT(shadowed, 20u) << "the mannequins' shadows fall on the ground";
    }
  }
}

TEST(VisibilityPass, SoftMasksOnAHostsGroundAreFractionsOfTheirSamples) {
  const rt::Scene& sc = testing_support::mannequins_scene();
  const HostGround ground;
  rt::Light sphere;
  sphere.position = Vec3(1.0f, 2.5f, 1.5f);
  sphere.radius = 0.8f;
  for (const int n : {4, 16}) {
    rt::RenderSettings settings;
    settings.light = sphere;
    settings.shadow_samples = n;
    settings.ao_rays = n;
    settings.ao_radius = 0.5f;
    const Masks masks = host_masks(sc, ground.host(rt::kAutomaticNormalOffset), settings, 1, 2);
    std::set<int> shadow_steps, ao_steps;
    for (int y = 0; y < HostGround::kHeight; ++y) {
      for (int x = 0; x < HostGround::kWidth; ++x) {
        const std::size_t p = static_cast<std::size_t>(y * HostGround::kWidth + x);
        for (const auto& [mask, steps] : {std::pair{masks.shadow[p], &shadow_steps},
                                          std::pair{masks.ambient_occlusion[p], &ao_steps}}) {
          const float k = std::round(mask * static_cast<float>(n));
          ASSERT_EQ(mask, k / static_cast<float>(n)) << x << ", " << y;
          ASSERT_GE(k, 0.0f);
          ASSERT_LE(k, static_cast<float>(n));
          if (!HostGround::has_surface(x, y)) {
            ASSERT_EQ(mask, 1.0f);
          }
          steps->insert(static_cast<int>(k));
        }
      }
    }
    EXPECT_TRUE(shadow_steps.count(0) && shadow_steps.count(n)) << "umbra and open light";
    EXPECT_GE(shadow_steps.size(), static_cast<std::size_t>(n / 2)) << "a penumbra of many steps";
    EXPECT_GE(ao_steps.size(), 2u) << "the ground near the feet is occluded";
  }
}

TEST(VisibilityPass, TheAutomaticOffsetIsAFractionOfTheScenesSize) {
  const rt::Scene& sc = testing_support::mannequins_scene();
  const HostGround ground;
  rt::RenderSettings settings;
  settings.light.position = Vec3(1.0f, 2.5f, 1.5f);
  const Aabb& world = sc.world_bounds();
  const float automatic = rt::kAutomaticOffsetScale * glm::length(world.upper - world.lower);
  EXPECT_EQ(host_masks(sc, ground.host(rt::kAutomaticNormalOffset), settings, 1, 1).shadow,
            host_masks(sc, ground.host(automatic), settings, 1, 1).shadow);
}

TEST(VisibilityPass, BadInputsAreRefusedByName) {
  const rt::Scene& sc = testing_support::mannequins_scene();
  const HostGround ground;
  JobSystem jobs(1);
  rt::RenderSettings settings;
  const auto refused = [&](const rt::HostSurfaces& surfaces, const rt::FrameBuffers& buffers,
                           const std::string& field) {
    const auto result = rt::Renderer().render_visibility(sc, surfaces, settings, buffers, jobs);
    ASSERT_FALSE(result.ok()) << field;
    EXPECT_EQ(result.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(result.status().message().find(field), std::string::npos) << result.status().message();
  };
  Masks masks;
  const rt::FrameBuffers buffers = mask_buffers(HostGround::kWidth, HostGround::kHeight, 1, masks);
  rt::HostSurfaces s = ground.host(0.0f);
  s.normal_offset = std::numeric_limits<float>::infinity();
  refused(s, buffers, "normal_offset");
  s.normal_offset = kNaN;
  refused(s, buffers, "normal_offset");
  s = ground.host(0.0f);
  s.normal = s.normal.first(10);
  refused(s, buffers, "surfaces.normal");
  s.normal = {};
  refused(s, buffers, "surfaces.normal");
  s = ground.host(0.0f);
  s.row_pitch.position = 10;
  refused(s, buffers, "row_pitch.position");
  s.row_pitch.position = HostGround::kWidth * sizeof(Vec3) + 2;
  refused(s, buffers, "row_pitch.position");
  s = ground.host(0.0f);
  const std::vector<float> short_error(5, 0.0f);
  s.position_error = short_error;
  refused(s, buffers, "surfaces.position_error");
  s = ground.host(0.0f);
  s.width = 0;
  refused(s, buffers, "surfaces.width");
  s = ground.host(0.0f);
  rt::FrameBuffers other = buffers;
  other.height = 3;
  refused(s, other, "masks.width x height");
  other = buffers;
  std::vector<float> depth(static_cast<std::size_t>(HostGround::kWidth * HostGround::kHeight));
  other.depth = depth;
  refused(s, other, "masks.depth");
  other = buffers;
  other.shadow = {};
  other.ambient_occlusion = {};
  refused(s, other, "masks.shadow");
  other = buffers;
  other.shadow = other.shadow.first(7);
  refused(s, other, "buffers.shadow");
  settings.ao_rays = -1;
  refused(s, buffers, "ao_rays");
}

}  // namespace
}  // namespace sinew
