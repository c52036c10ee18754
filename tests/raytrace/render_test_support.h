// Shared by the render tests (sinew_render_tests): the triangle tests the
// packet and renderer tests run with, a random float in [0, 1), and the
// scene of two mannequins on a ground quad that the packet, static-tile,
// tile-stage and renderer tests trace (and the mannequins alone, over a
// host's ground that is not in the scene).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <random>

#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/idle_mannequin.h"

namespace sinew::testing_support {

inline constexpr rt::TriangleTest kTests[] = {rt::TriangleTest::kFast, rt::TriangleTest::kWatertight};
inline constexpr float kInf = std::numeric_limits<float>::infinity();

inline float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }

// Two mannequins on a ground quad, one idling inside its pose space, one
// kicking out of it (its escaped triangles go through the fallback);
// without the quad, the mannequins alone (standing on y = 0).
inline std::unique_ptr<rt::Scene> make_scene(bool with_ground = true) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t instance = scene->add_instance(character).value();
    const Affine3 place = Affine3::translation(Vec3(0.9f * static_cast<float>(i) - 0.45f, 0.0f, 0.0f));
    EXPECT_TRUE(scene
                    ->set_bones(instance, testing_support::clip_pose(m.model, i == 1 ? "kick" : "idle",
                                                                     i == 1 ? 0.4 : 0.3, place))
                    .ok());
  }
  if (with_ground) {
    rt::StaticMeshDesc ground;
    ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
    ground.triangles = {{0, 2, 1}, {1, 2, 3}};
    EXPECT_TRUE(scene->add_static_mesh(ground).ok());
  }
  JobSystem jobs(2);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return scene;
}

inline const rt::Scene& scene() {
  static const std::unique_ptr<rt::Scene> s = make_scene();
  return *s;
}

inline const rt::Scene& mannequins_scene() {
  static const std::unique_ptr<rt::Scene> s = make_scene(false);
  return *s;
}

}  // namespace sinew::testing_support
