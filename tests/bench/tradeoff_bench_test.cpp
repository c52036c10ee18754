// The reusable pieces of `sinew-bench tradeoff`: the knee rule and the crack
// test's mesh and leak count.
#include "tests/bench/tradeoff_bench.h"

#include <gtest/gtest.h>

namespace sinew::bench {
namespace {

TEST(TradeoffKnee, PicksTheFewestSamplesBelowTheThresholdAtTheSmallestPadding) {
  const std::vector<KneePoint> points = {
      {"arbitrary", 4, 0.0, 90.0, 3e-2},  {"arbitrary", 16, 0.0, 80.0, 5e-5},
      {"arbitrary", 62, 0.0, 70.0, 0.0},  {"arbitrary", 8, 0.05, 85.0, 0.0},  // padded: not the knee's curve
      {"clips", 4, 0.0, 95.0, 1e-4},      // at the threshold: not below it
      {"clips", 250, 0.0, 60.0, 2e-5},
  };
  const auto arbitrary = find_knee(points, "arbitrary", 1e-4);
  ASSERT_TRUE(arbitrary.has_value());
  EXPECT_EQ(arbitrary->samples_used, 16);
  EXPECT_EQ(arbitrary->fps, 80.0);
  const auto clips = find_knee(points, "clips", 1e-4);
  ASSERT_TRUE(clips.has_value());
  EXPECT_EQ(clips->samples_used, 250);
}

TEST(TradeoffKnee, NoneWhenNoPointGetsThereOrTheModeIsMissing) {
  const std::vector<KneePoint> points = {{"limits", 4, 0.01, 90.0, 1e-2}, {"limits", 1000, 0.01, 50.0, 2e-4}};
  EXPECT_FALSE(find_knee(points, "limits", 1e-4).has_value());
  EXPECT_FALSE(find_knee(points, "clip", 1e-4).has_value());
}

// The icosphere is closed: 3 subdivisions give 10 * 4^3 + 2 = 642 vertices
// and 30 * 4^3 = 1920 edges, each target of one ray (vertex, edge midpoint,
// a random point on the edge): 642 + 2 * 1920 rays. A mesh whose midpoints
// were not shared would have more vertices and edges.
TEST(TradeoffCrack, WatertightTestLeaksNoRayThroughSharedEdgesAndVertices) {
  const CrackResult watertight = crack_test(true, 3, 7);
  EXPECT_EQ(watertight.rays, 642u + 2u * 1920u);
  EXPECT_EQ(watertight.leaked, 0u);
}

}  // namespace
}  // namespace sinew::bench
