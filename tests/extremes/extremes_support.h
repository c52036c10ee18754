// Shared by the numerical-extremes suite (docs/ROBUSTNESS.md): a baked model
// posed into a scene, rendered with every AOV, and every pixel compared with
// brute force over the skinned triangles (tests/support/brute_force.h).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animation/pose.h"
#include "animation/skeleton.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/aov_frame.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew::extremes {

using testing_support::BakedModel;
using testing_support::SoupTriangle;

// Skinning matrices for a local pose (joint_count entries), placed by `instance`.
inline Expected<std::vector<Affine3>> skin_local_pose(const anim::Skeleton& skeleton,
                                                      std::span<const anim::JointTransform> local,
                                                      const Affine3& instance = Affine3::identity()) {
  std::vector<Affine3> model(skeleton.joint_count());
  std::vector<Affine3> skin(skeleton.joint_count());
  SINEW_RETURN_IF_ERROR(anim::local_to_model(skeleton, local, model));
  SINEW_RETURN_IF_ERROR(anim::skinning_matrices(skeleton, model, instance, skin));
  return skin;
}

// One character instance of `baked` posed by `bones`, the frame prepared.
inline rt::Scene posed_scene(const BakedModel& baked, std::span<const Affine3> bones,
                             rt::FrameStats* stats_out = nullptr) {
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(baked.model.mesh, baked.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene.add_instance(character).value();
  EXPECT_TRUE(scene.set_bones(instance, bones).ok());
  JobSystem jobs(2);
  auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
  EXPECT_TRUE(stats.ok()) << stats.status().message();
  if (stats_out != nullptr && stats.ok()) *stats_out = *stats;
  return scene;
}

struct ImageCheck {
  std::size_t pixels = 0;
  std::size_t hits = 0;       // pixels where brute force hits something
  std::size_t wrong = 0;      // AOVs disagreeing with brute force
  std::size_t not_finite = 0; // NaN (or inf where not a miss) in colour, depth or normal
  std::string first;
};

inline bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Renders `scene` (colour, depth, normal, triangle and instance ids; shadows
// on) and checks every pixel of every AOV against brute force, for both
// triangle tests.
inline ImageCheck render_and_compare(const rt::Scene& scene, const rt::CameraDesc& desc, int width, int height) {
  ImageCheck check;
  const auto camera = rt::PinholeCamera::create(desc, width, height);
  EXPECT_TRUE(camera.ok()) << camera.status().message();
  if (!camera.ok()) return check;
  const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
  const testing_support::ScreenBinner binner(soup, *camera);
  testing_support::AovFrame frame(width, height);
  const auto& color = frame.rgba32f;
  const auto& depth = frame.depth;
  const auto& normal = frame.normal;
  const auto& triangle = frame.triangle_id;
  const auto& instance = frame.instance_id;
  JobSystem jobs(2);
  for (const rt::TriangleTest test : {rt::TriangleTest::kFast, rt::TriangleTest::kWatertight}) {
    frame.poison();
    const rt::FrameBuffers buffers = frame.buffers();
    rt::RenderSettings settings;
    settings.triangle_test = test;
    settings.light.position = camera->eye() + Vec3(1.0f, 3.0f, 2.0f) * glm::length(desc.target - desc.eye);
    rt::Renderer renderer;
    const auto stats = renderer.render(scene, *camera, settings, buffers, jobs);
    EXPECT_TRUE(stats.ok()) << stats.status().message();
    if (!stats.ok()) return check;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        ++check.pixels;
        const Ray ray = camera->ray(x, y);
        const Hit ref = binner.nearest(soup, ray, x, y, test);
        Hit ours;
        ours.triangle_id = triangle[i];
        ours.instance_id = instance[i];
        ours.t = depth[i] / glm::length(ray.direction);
        const bool colour_ok = std::isfinite(color[4 * i]) && std::isfinite(color[4 * i + 1]) &&
                               std::isfinite(color[4 * i + 2]) && std::isfinite(color[4 * i + 3]);
        const bool aov_ok = ours.valid() ? (std::isfinite(depth[i]) && finite3(normal[i]))
                                         : (std::isinf(depth[i]) && depth[i] > 0.0f && finite3(normal[i]));
        if (!colour_ok || !aov_ok) ++check.not_finite;
        check.hits += ref.valid() ? 1 : 0;
        if (!testing_support::same_nearest(ours, ref, soup, ray, test) && check.wrong++ == 0) {
          check.first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") " +
                        (test == rt::TriangleTest::kFast ? "fast" : "watertight") + ": ours tri " +
                        std::to_string(ours.triangle_id) + " depth " + std::to_string(depth[i]) + ", ref tri " +
                        std::to_string(ref.triangle_id) + " t " + std::to_string(ref.t);
        }
      }
    }
  }
  return check;
}

inline void expect_correct_image(const ImageCheck& c, const std::string& what, std::size_t min_hits = 50) {
  EXPECT_EQ(c.wrong, 0u) << what << ": " << c.pixels << " pixels; first: " << c.first;
  EXPECT_EQ(c.not_finite, 0u) << what << ": NaN or inf in an AOV";
  EXPECT_GE(c.hits, min_hits) << what << ": the character is not in view, the comparison proves little";
}

}  // namespace sinew::extremes
