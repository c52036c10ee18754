// Culling whole characters (FrameOptions::visibility, scene/visibility.h):
// a grid of mannequins, most of them off-screen, some of those between a low
// light and the visible ground. Culled characters never change an image (with
// culling on and off, 1 and 2 threads, point and directional lights, poses
// advancing frame by frame, some outside the pose space), culled ones are
// not skinned nor in the top level, the off-screen ones kept do shadow the
// view (hard and area lights, ambient occlusion), and an instance's conservative bounds hold its skinned vertices in
// any pose.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/frame_visibility.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

constexpr int kColumns = 8;
constexpr int kInstances = kColumns * kColumns;

struct Crowd {
  std::unique_ptr<rt::Scene> scene;
  std::vector<std::uint32_t> ids;
};

// kInstances mannequins 1.2 apart on a ground quad; every third one kicks,
// out of the idle pose space (its escaped triangles take the fallback).
Crowd make_crowd() {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  Crowd crowd;
  crowd.scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = crowd.scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  for (int i = 0; i < kInstances; ++i) crowd.ids.push_back(crowd.scene->add_instance(character).value());
  rt::StaticMeshDesc ground;
  ground.positions = {{-30, 0, -30}, {30, 0, -30}, {-30, 0, 30}, {30, 0, 30}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  EXPECT_TRUE(crowd.scene->add_static_mesh(ground).ok());
  return crowd;
}

// Frame `f`'s poses: each instance 0.37 s after the one before.
void pose_crowd(Crowd& crowd, int f) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  for (int i = 0; i < kInstances; ++i) {
    if (!crowd.scene->contains(crowd.ids[static_cast<std::size_t>(i)])) continue;
    const float x = 1.2f * static_cast<float>(i % kColumns - kColumns / 2);
    const float z = -1.2f * static_cast<float>(i / kColumns);
    const double t = 0.2 + 0.1 * f + 0.37 * i;
    const std::vector<Affine3> bones = testing_support::clip_pose(
        m.model, i % 3 == 0 ? "kick" : "idle", i % 3 == 0 ? std::fmod(t, 0.8) : t, Affine3::translation(Vec3(x, 0, z)));
    EXPECT_TRUE(crowd.scene->set_bones(crowd.ids[static_cast<std::size_t>(i)], bones).ok());
  }
}

struct Image {
  std::vector<std::uint8_t> color;
  std::vector<float> depth;
  std::vector<std::uint32_t> instance;
  rt::FrameStats frame;
};

// Looks down at a patch of ground left of the grid's middle rows; the light
// sits low beyond the grid's right, so those rows' shadows stretch into the
// view while the front and back rows lie outside both.
rt::PinholeCamera crowd_camera() {
  return rt::PinholeCamera::create({Vec3(-7.0f, 6.0f, -4.0f), Vec3(-6.0f, 0.0f, -4.0f), Vec3(0, 1, 0), 30.0f}, 96, 80)
      .value();
}

// The lights the cull is checked with: hard point and directional lights,
// then soft ones (a sphere light, the sun, a rectangle) and ambient
// occlusion, whose rays reach further than the hard ones'.
enum class Lighting { kPoint, kDirectional, kSphere, kSun, kRect, kAmbientOcclusion };
constexpr Lighting kLightings[] = {Lighting::kPoint, Lighting::kDirectional, Lighting::kSphere,
                                   Lighting::kSun,   Lighting::kRect,        Lighting::kAmbientOcclusion};

rt::RenderSettings crowd_settings(Lighting lighting) {
  rt::RenderSettings settings;
  settings.shadow_samples = 2;
  rt::Light& light = settings.light;
  light.position = Vec3(9.0f, 1.2f, -4.0f);
  switch (lighting) {
    case Lighting::kPoint: break;
    case Lighting::kDirectional:
    case Lighting::kSun:
      light.kind = rt::Light::Kind::kDirectional;
      light.direction = Vec3(1.0f, 0.35f, 0.1f);
      if (lighting == Lighting::kSun) light.angular_radius = 0.2f;
      break;
    case Lighting::kSphere: light.radius = 1.5f; break;
    case Lighting::kRect:
      light.kind = rt::Light::Kind::kRect;
      light.edge_u = Vec3(0.0f, 0.0f, 3.0f);
      light.edge_v = Vec3(0.0f, 1.5f, 0.0f);
      break;
    case Lighting::kAmbientOcclusion:
      settings.shadows = false;
      settings.ao_rays = 2;
      settings.ao_radius = 1.5f;
      break;
  }
  return settings;
}

Image render(rt::Scene& scene, bool cull, Lighting lighting, int threads, bool shadows = true) {
  const rt::PinholeCamera camera = crowd_camera();
  rt::RenderSettings settings = crowd_settings(lighting);
  settings.shadows = settings.shadows && shadows;
  if (!shadows) settings.ao_rays = 0;
  JobSystem jobs(threads);
  rt::FrameOptions options;
  if (cull) options.visibility = rt::frame_visibility(camera, settings);
  Image image;
  image.frame = scene.prepare_frame(options, jobs).value();
  const std::size_t n = static_cast<std::size_t>(camera.width() * camera.height());
  image.color.resize(4 * n);
  image.depth.resize(n);
  image.instance.resize(n);
  rt::FrameBuffers buffers{camera.width(), camera.height(), image.color, {}, image.depth, {}, {}, image.instance,
                           {}, {}, {}, {}, {}, {}};
  EXPECT_TRUE(rt::Renderer().render(scene, camera, settings, buffers, jobs).ok());
  return image;
}

TEST(CrowdCull, CulledCharactersNeverChangeTheImage) {
  for (const Lighting lighting : kLightings) {
    Crowd crowd = make_crowd();
    for (int f = 0; f < 3; ++f) {
      pose_crowd(crowd, f);
      const Image off = render(*crowd.scene, false, lighting, 2);
      EXPECT_EQ(off.frame.skinned_instances, static_cast<std::uint32_t>(kInstances));
      EXPECT_EQ(off.frame.culled_instances, 0u);
      for (const int threads : {1, 2}) {
        const Image on = render(*crowd.scene, true, lighting, threads);
        SCOPED_TRACE(::testing::Message() << "lighting " << static_cast<int>(lighting) << " frame " << f
                                          << " threads " << threads);
        EXPECT_EQ(on.color, off.color);
        EXPECT_EQ(on.depth, off.depth);
        EXPECT_EQ(on.instance, off.instance);
        EXPECT_EQ(on.frame.skinned_instances + on.frame.culled_instances, static_cast<std::uint32_t>(kInstances));
        EXPECT_GT(on.frame.culled_instances, static_cast<std::uint32_t>(kInstances / 8));
        EXPECT_GT(on.frame.skinned_instances, 0u);
        // Culled instances were neither skinned nor put in the top level.
        std::uint32_t culled = 0;
        for (const rt::InstanceFrame& frame : crowd.scene->instances()) {
          if (!frame.culled) continue;
          ++culled;
          for (const Aabb& box : frame.bone_world_boxes) EXPECT_TRUE(box.is_empty());
          EXPECT_TRUE(frame.escaped_triangles.empty());
        }
        EXPECT_EQ(culled, on.frame.culled_instances);
        for (const rt::TopLevelObject& object : crowd.scene->top_level().objects()) {
          if (object.kind != rt::TopLevelObject::Kind::kStatic) {
            EXPECT_FALSE(crowd.scene->instances()[object.index].culled);
          }
        }
      }
    }
  }
}

// Without shadows only the view keeps; with them, the off-screen instances
// between the light and the view are kept too, and they do shadow the view:
// removing them changes the image.
TEST(CrowdCull, OffScreenCastersAreKeptAndShadowTheView) {
  for (const Lighting lighting : kLightings) {
    SCOPED_TRACE(::testing::Message() << "lighting " << static_cast<int>(lighting));
    Crowd crowd = make_crowd();
    pose_crowd(crowd, 1);
    const Image view_only = render(*crowd.scene, true, lighting, 2, false);
    std::vector<bool> in_view;
    for (const rt::InstanceFrame& frame : crowd.scene->instances()) in_view.push_back(!frame.culled);
    const Image with_shadows = render(*crowd.scene, true, lighting, 2);
    EXPECT_GT(with_shadows.frame.skinned_instances, view_only.frame.skinned_instances);
    std::vector<std::uint32_t> casters;
    for (std::size_t i = 0; i < in_view.size(); ++i) {
      if (!in_view[i] && !crowd.scene->instances()[i].culled) casters.push_back(crowd.ids[i]);
    }
    ASSERT_FALSE(casters.empty());
    // The off-screen casters never show in the image themselves.
    for (const std::uint32_t id : with_shadows.instance) {
      for (const std::uint32_t caster : casters) EXPECT_NE(id, caster);
    }
    for (const std::uint32_t caster : casters) ASSERT_TRUE(crowd.scene->remove(caster).ok());
    pose_crowd(crowd, 1);
    const Image without = render(*crowd.scene, false, lighting, 2);
    EXPECT_NE(without.color, with_shadows.color);
  }
}

// instance_bounds holds every skinned vertex: sampled, kicked and distorted
// poses (scaled, sheared, far from the origin, a zero-scale bone).
TEST(CrowdCull, InstanceBoundsHoldTheSkinnedVerticesInAnyPose) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene.add_instance(character).value();
  std::mt19937 g(7);
  JobSystem jobs(2);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Affine3> bones =
        testing_support::clip_pose(m.model, trial % 2 ? "kick" : "idle", 0.05 * trial,
                                   Affine3::translation(Vec3(0.0f, 0.0f, trial % 4 == 3 ? 1e4f : 0.0f)));
    if (trial >= 20) {
      for (Affine3& bone : bones) {
        for (Vec4& row : bone.rows) {
          row.x += 0.3f * (static_cast<float>(g() % 1000) / 1000.0f - 0.5f);
          row.y += 0.3f * (static_cast<float>(g() % 1000) / 1000.0f - 0.5f);
          row.z += 0.3f * (static_cast<float>(g() % 1000) / 1000.0f - 0.5f);
          row.w += 2.0f * (static_cast<float>(g() % 1000) / 1000.0f - 0.5f);
        }
      }
      Affine3 flat;  // a zero-scale bone
      for (Vec4& row : flat.rows) row = Vec4(0.0f, 0.0f, 0.0f, row.w);
      bones[static_cast<std::size_t>(trial) % bones.size()] = flat;
    }
    ASSERT_TRUE(scene.set_bones(instance, bones).ok());
    ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
    const rt::InstanceFrame& frame = scene.instances()[0];
    const Aabb bounds = rt::instance_bounds(frame.skinning, scene.characters()[0].influence_bounds);
    for (const Vec3& p : frame.positions) ASSERT_TRUE(bounds.contains(p)) << trial;
  }
}

}  // namespace
}  // namespace sinew
