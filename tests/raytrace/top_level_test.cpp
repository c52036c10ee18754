// The top level's object runs (accel/top_level.h): one per character
// instance and one per static mesh, covering every object once, each run's
// box holding its members' boxes.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "raytrace/accel/top_level.h"

namespace sinew {
namespace {

// TopLevel's runs: one per character instance (its bones and fallback,
// consecutive) and one per static mesh, covering every object once, each
// run's box holding every coordinate of its members' boxes (an inverted
// one's too: the tree skips it, the flat cull tests it).
TEST(TopLevel, RunsGroupEachInstanceAndHoldTheirMembers) {
  using Kind = rt::TopLevelObject::Kind;
  const auto box = [](float lo, float hi) { return Aabb{Vec3(lo), Vec3(hi)}; };
  std::vector<rt::TopLevelObject> objects = {
      {Kind::kBone, 0, 0, box(0.0f, 1.0f)},    {Kind::kBone, 0, 1, box(-3.0f, -2.0f)},
      {Kind::kFallback, 0, 0, box(5.0f, 4.0f)},  // inverted
      {Kind::kBone, 1, 0, box(10.0f, 11.0f)},  {Kind::kBone, 1, 3, Aabb{Vec3(12.0f, 9.0f, 12.0f), Vec3(12.0f, 13.0f, 12.0f)}},
      {Kind::kStatic, 0, 0, box(-1.0f, 1.0f)}, {Kind::kStatic, 1, 0, box(2.0f, 3.0f)},
      {Kind::kBone, 2, 0, box(20.0f, 21.0f)}};
  const std::vector<rt::TopLevelObject> copy = objects;
  rt::TopLevel top;
  ASSERT_TRUE(top.build(std::move(objects), rt::KdBuildOptions{}).ok());
  const std::span<const rt::ObjectRun> runs = top.runs();
  ASSERT_EQ(runs.size(), 5u);
  const std::uint32_t firsts[5] = {0, 3, 5, 6, 7}, counts[5] = {3, 2, 1, 1, 1};
  for (std::size_t r = 0; r < runs.size(); ++r) {
    EXPECT_EQ(runs[r].first, firsts[r]) << r;
    EXPECT_EQ(runs[r].count, counts[r]) << r;
  }
  EXPECT_EQ(runs[0].box.lower, Vec3(-3.0f));
  EXPECT_EQ(runs[0].box.upper, Vec3(5.0f));
  EXPECT_EQ(runs[1].box.lower, Vec3(10.0f, 9.0f, 10.0f));
  EXPECT_EQ(runs[1].box.upper, Vec3(12.0f, 13.0f, 12.0f));
  for (const rt::ObjectRun& run : runs) {
    for (std::uint32_t i = run.first; i < run.first + run.count; ++i) {
      for (int a = 0; a < 3; ++a) {
        for (const float c : {copy[i].box.lower[a], copy[i].box.upper[a]}) {
          EXPECT_LE(run.box.lower[a], c) << i;
          EXPECT_GE(run.box.upper[a], c) << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace sinew
