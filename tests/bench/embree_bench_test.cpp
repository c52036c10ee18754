// The Embree contender of `sinew-bench embree` (tests/bench/embree_tracer.h),
// run (not timed) on the mannequin: in each Embree mode and at each ray
// width (single rays and 4/8/16-wide packets), the primary hits must be
// brute force's on every pixel of two animated frames, the second after a
// rebuild or a refit, and the colour image must match Sinew's renderer on
// the pixels where both hit the same triangle.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "character/framing.h"
#include "raytrace/render/renderer.h"
#include "runtime/jobs/job_system.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/embree_tracer.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew::bench {
namespace {

// Not a multiple of the 16-pixel tile: the last row and column of tiles are
// 2 pixels wide, so partial 4x2 blocks (masked lanes) and a corner tile of a
// single block (16-wide packets fall back to one 8-wide) are traced too.
constexpr int kSize = 66;

// The bench measures every (mode, width) pair, so each is checked here.
class EmbreeTracerTest : public ::testing::TestWithParam<std::tuple<EmbreeMode, EmbreeWidth>> {};

TEST_P(EmbreeTracerTest, PrimaryHitsEqualBruteForceOverTwoFrames) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  JobSystem jobs(2);
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene.add_instance(character).value();
  const Aabb rest = character::rest_bounds(m.model);
  const int up = character::up_axis_of(rest);
  ASSERT_TRUE(scene.add_static_mesh(character::ground_plane_for(rest, 1)).ok());

  const auto [mode, width] = GetParam();
  auto tracer = EmbreeTracer::create(mode, 2);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  rt::Renderer renderer;
  rt::RenderSettings settings;
  std::optional<rt::PinholeCamera> camera;
  // The kick leaves the idle pose space, so the second frame also moves
  // triangles far from where the first frame's BVH had them.
  for (const double t : {0.0, 0.6}) {
    ASSERT_TRUE(scene.set_bones(instance, testing_support::clip_pose(m.model, "kick", t)).ok());
    ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
    if (!camera) {
      const Aabb posed = character::posed_bounds(scene);
      settings.light.position = character::default_light(posed, up);
      camera = rt::PinholeCamera::create(character::default_camera(posed, up, kSize, kSize), kSize, kSize).value();
    }
    const auto built = (*tracer)->update(scene);
    ASSERT_TRUE(built.ok()) << built.status().message();

    std::vector<Hit> hits(kSize * kSize);
    std::vector<std::uint8_t> color(4 * kSize * kSize);
    const auto rendered = (*tracer)->render(scene, *camera, settings, color, hits, jobs, width);
    ASSERT_TRUE(rendered.ok()) << rendered.status().message();

    // Sinew's renderer on the same scene, for the colours.
    std::vector<std::uint8_t> sinew_color(4 * kSize * kSize);
    std::vector<std::uint32_t> sinew_triangle(kSize * kSize);
    rt::FrameBuffers buffers;
    buffers.width = buffers.height = kSize;
    buffers.color_rgba8 = sinew_color;
    buffers.triangle_id = sinew_triangle;
    ASSERT_TRUE(renderer.render(scene, *camera, settings, buffers, jobs).ok());

    const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(scene);
    const testing_support::ScreenBinner binner(soup, *camera);
    int hit_pixels = 0, same_triangle = 0;
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const std::size_t p = static_cast<std::size_t>(y * kSize + x);
        const Ray ray = camera->ray(x, y);
        const Hit ref = binner.nearest(soup, ray, x, y, rt::TriangleTest::kWatertight);
        ASSERT_TRUE(testing_support::same_nearest(hits[p], ref, soup, ray, rt::TriangleTest::kWatertight))
            << "t=" << t << " pixel " << x << "," << y << ": embree t " << hits[p].t << " tri "
            << hits[p].triangle_id << " inst " << hits[p].instance_id << ", brute force t " << ref.t << " tri "
            << ref.triangle_id << " inst " << ref.instance_id;
        if (hits[p].valid()) ++hit_pixels;
        if (!hits[p].valid() || sinew_triangle[p] != hits[p].triangle_id) continue;
        ++same_triangle;
        // Same surface math; only the sRGB tables differ (by at most one step).
        for (std::size_t c = 0; c < 3; ++c) {
          EXPECT_LE(std::abs(int{color[4 * p + c]} - int{sinew_color[4 * p + c]}), 1) << x << "," << y;
        }
      }
    }
    EXPECT_EQ(static_cast<std::uint64_t>(hit_pixels), rendered->primary_hits);
    EXPECT_GT(hit_pixels, kSize * kSize / 10);  // the character and the ground fill the view
    EXPECT_GT(same_triangle, hit_pixels / 2);
    EXPECT_GT(rendered->shadow_rays, 0u);
  }
}

// `sinew-bench embree --layout grid`: the staged crowd stands where the
// render command's grid puts it (character/framing.h), one Embree geometry
// per copy, and the peer's primary hits are brute force's on every pixel,
// with every copy in view.
TEST(EmbreeTracerGrid, ACrowdInTheGridLayoutIsTracedAsBruteForceTracesIt) {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  JobSystem jobs(2);
  constexpr int kCopies = 5;
  BenchStage stage;
  ASSERT_TRUE(stage_instances(m.model, m.bake.fuzzy.view(), kCopies, stage, character::Layout::kGrid).ok());
  ASSERT_EQ(stage.placements.size(), static_cast<std::size_t>(kCopies));
  for (int i = 0; i < kCopies; ++i) {
    const Vec3 ours = stage.placements[static_cast<std::size_t>(i)].translation_part();
    const Vec3 grid =
        character::instance_placement(stage.rest, i, kCopies, character::Layout::kGrid).translation_part();
    EXPECT_EQ(ours, grid) << "copy " << i;
  }
  ASSERT_TRUE(pose_instances(m.model, *m.model.find_clip("walk"), 0.2, stage).ok());
  ASSERT_TRUE(stage.scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  const Aabb posed = character::posed_bounds(stage.scene);
  const auto camera =
      rt::PinholeCamera::create(character::default_camera(posed, stage.up, kSize, kSize), kSize, kSize).value();
  auto tracer = EmbreeTracer::create(EmbreeMode::kRefit, 2);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  ASSERT_TRUE((*tracer)->update(stage.scene).ok());
  rt::RenderSettings settings;
  settings.light.position = character::default_light(posed, stage.up);
  std::vector<Hit> hits(kSize * kSize);
  std::vector<std::uint8_t> color(4 * kSize * kSize);
  ASSERT_TRUE((*tracer)->render(stage.scene, camera, settings, color, hits, jobs, EmbreeWidth::k8).ok());
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(stage.scene);
  const testing_support::ScreenBinner binner(soup, camera);
  std::vector<int> pixels(kCopies + 1, 0);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const Hit& h = hits[static_cast<std::size_t>(y * kSize + x)];
      const Ray ray = camera.ray(x, y);
      const Hit ref = binner.nearest(soup, ray, x, y, rt::TriangleTest::kWatertight);
      ASSERT_TRUE(testing_support::same_nearest(h, ref, soup, ray, rt::TriangleTest::kWatertight))
          << "pixel " << x << "," << y;
      if (h.valid()) ++pixels.at(h.instance_id);
    }
  }
  for (int i = 0; i <= kCopies; ++i) EXPECT_GT(pixels[static_cast<std::size_t>(i)], 0) << "instance " << i;
}

// "RebuildLow_rtcIntersect8": the mode and the Embree call of the width.
std::string case_name(const ::testing::TestParamInfo<EmbreeTracerTest::ParamType>& info) {
  const auto [mode, width] = info.param;
  const char* modes[] = {"RebuildLow", "RebuildMedium", "Refit"};  // EmbreeMode's order
  return std::string(modes[static_cast<int>(mode)]) + "_" + embree_width_name(width);
}

INSTANTIATE_TEST_SUITE_P(ModesAndWidths, EmbreeTracerTest,
                         ::testing::Combine(::testing::Values(EmbreeMode::kRebuildLow, EmbreeMode::kRebuildMedium,
                                                              EmbreeMode::kRefit),
                                            ::testing::ValuesIn(kEmbreeWidths)),
                         case_name);

}  // namespace
}  // namespace sinew::bench
