// Tests of the binned-SAH BVH builder against independent references: a
// recursive check of every structural promise the header makes, a segment
// walk written here against brute force over the boxes, and hand-built
// cases (two clusters, identical centres, a geometric series that defeats
// the SAH's bins, bad input).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "raytrace/accel/box_bvh.h"
#include "raytrace/accel/kd_tree.h"

namespace sinew::rt {
namespace {

float unit(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

// Boxes with the awkward cases: shared grid coordinates, flat and point
// boxes, duplicates, a few huge ones, empty ones (left out).
std::vector<Aabb> awkward_boxes(std::mt19937& rng, int count) {
  std::vector<Aabb> boxes;
  const auto grid = [&] { return static_cast<float>(rng() % 33) * 0.25f - 4.0f; };
  for (int i = 0; i < count; ++i) {
    const std::uint32_t kind = rng() % 12;
    Aabb b;
    if (kind == 0 && !boxes.empty()) {
      b = boxes[rng() % boxes.size()];
    } else if (kind == 1) {
      b = Aabb::from_point(Vec3(grid(), grid(), grid()));
    } else if (kind == 2) {
      b = Aabb::empty();
    } else if (kind == 3) {
      b = Aabb::from_corners(Vec3(-50.0f * unit(rng)), Vec3(50.0f * unit(rng)));
    } else {
      const Vec3 p(grid(), grid(), grid());
      b = Aabb::from_corners(p, p + Vec3(unit(rng), kind == 4 ? 0.0f : unit(rng), unit(rng)));
    }
    boxes.push_back(b);
  }
  return boxes;
}

bool same_box(const Aabb& a, const Aabb& b) { return a.lower == b.lower && a.upper == b.upper; }

// Walks the tree from `node` checking what box_bvh.h promises; returns the
// node's box as recomputed from the boxes below it, and records the items.
Aabb check_node(const BoxBvh& bvh, std::span<const Aabb> boxes, const BvhBuildOptions& options, std::uint32_t node,
                int depth, std::vector<int>& listed, int& max_depth) {
  max_depth = std::max(max_depth, depth);
  const BvhNode& n = bvh.nodes[node];
  Aabb below;
  if (n.is_leaf()) {
    EXPECT_LE(n.count, static_cast<std::uint32_t>(options.max_leaf_items));
    EXPECT_LE(std::size_t{n.first} + n.count, bvh.items.size());
    for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
      const std::uint32_t item = bvh.items[i];
      EXPECT_LT(item, boxes.size());
      if (i > n.first) {
        EXPECT_LT(bvh.items[i - 1], item) << "leaf items increase";
      }
      ++listed[item];
      below.extend(boxes[item]);
    }
  } else {
    EXPECT_GT(n.first, node) << "children come after their parent";
    EXPECT_LT(std::size_t{n.first} + 1, bvh.nodes.size());
    below.extend(check_node(bvh, boxes, options, n.first, depth + 1, listed, max_depth));
    below.extend(check_node(bvh, boxes, options, n.first + 1, depth + 1, listed, max_depth));
  }
  EXPECT_TRUE(same_box(n.box, below)) << "node " << node << "'s box is the union of the boxes below it";
  return below;
}

void check_tree(const BoxBvh& bvh, std::span<const Aabb> boxes, const BvhBuildOptions& options) {
  std::vector<int> listed(boxes.size(), 0);
  int max_depth = 0;
  std::size_t non_empty = 0;
  for (const Aabb& b : boxes) non_empty += b.is_empty() ? 0 : 1;
  if (non_empty == 0) {
    EXPECT_TRUE(bvh.nodes.empty());
    return;
  }
  ASSERT_FALSE(bvh.nodes.empty());
  check_node(bvh, boxes, options, 0, 0, listed, max_depth);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ(listed[i], boxes[i].is_empty() ? 0 : 1) << "box " << i << " listed once (none if empty)";
  }
  EXPECT_EQ(bvh.items.size(), non_empty);
  EXPECT_EQ(bvh.stats.node_count, bvh.nodes.size());
  EXPECT_EQ(bvh.stats.item_count, bvh.items.size());
  EXPECT_EQ(bvh.stats.max_depth, max_depth);
  EXPECT_LE(max_depth, kMaxTraversalDepth);
}

// Whether the segment o + t d, t in [t0, t1], meets `box` (slabs, written
// here: the traversals' own clip is not used).
bool segment_meets(const Aabb& box, const Vec3& o, const Vec3& d, float t0, float t1) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) {
      if (o[a] < box.lower[a] || o[a] > box.upper[a]) return false;
      continue;
    }
    float n = (box.lower[a] - o[a]) / d[a], f = (box.upper[a] - o[a]) / d[a];
    if (n > f) std::swap(n, f);
    t0 = std::max(t0, n);
    t1 = std::min(t1, f);
  }
  return t0 <= t1;
}

void collect(const BoxBvh& bvh, std::uint32_t node, const Vec3& o, const Vec3& d, std::set<std::uint32_t>& out) {
  const BvhNode& n = bvh.nodes[node];
  if (!segment_meets(n.box, o, d, 0.0f, 1.0f)) return;
  if (n.is_leaf()) {
    for (std::uint32_t i = n.first; i < n.first + n.count; ++i) out.insert(bvh.items[i]);
    return;
  }
  collect(bvh, n.first, o, d, out);
  collect(bvh, n.first + 1, o, d, out);
}

TEST(BoxBvh, KeepsEveryPromiseOnAwkwardBoxes) {
  std::mt19937 rng(7);
  for (const int leaf : {1, 4, 32}) {
    for (const int count : {0, 1, 2, 3, 50, 700}) {
      const std::vector<Aabb> boxes = awkward_boxes(rng, count);
      const BvhBuildOptions options{.max_leaf_items = leaf, .bins = 16};
      const Expected<BoxBvh> bvh = build_box_bvh(boxes, options);
      ASSERT_TRUE(bvh.ok()) << bvh.status().message();
      SCOPED_TRACE(testing::Message() << "leaf " << leaf << ", " << count << " boxes");
      check_tree(*bvh, boxes, options);
    }
  }
}

TEST(BoxBvh, AWalkOfTheNodeBoxesFindsEveryBoxASegmentMeets) {
  std::mt19937 rng(11);
  const std::vector<Aabb> boxes = awkward_boxes(rng, 2000);
  const Expected<BoxBvh> bvh = build_box_bvh(boxes, {.max_leaf_items = 8, .bins = 16});
  ASSERT_TRUE(bvh.ok());
  for (int s = 0; s < 300; ++s) {
    const Vec3 o(12.0f * unit(rng) - 6.0f, 12.0f * unit(rng) - 6.0f, 12.0f * unit(rng) - 6.0f);
    Vec3 d(12.0f * unit(rng) - 6.0f, 12.0f * unit(rng) - 6.0f, 12.0f * unit(rng) - 6.0f);
    if (s % 10 == 0) d.y = 0.0f;  // parallel to a slab
    std::set<std::uint32_t> reached;
    collect(*bvh, 0, o, d, reached);
    for (std::uint32_t i = 0; i < boxes.size(); ++i) {
      if (boxes[i].is_empty() || !segment_meets(boxes[i], o, d, 0.0f, 1.0f)) continue;
      EXPECT_TRUE(reached.count(i)) << "segment " << s << " meets box " << i << " but the walk misses it";
    }
  }
}

TEST(BoxBvh, SplitsTwoDistantClustersAtTheRoot) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 10; ++i) {
    const float x = static_cast<float>(i) * 0.1f;
    boxes.push_back(Aabb::from_corners(Vec3(x, 0.0f, 0.0f), Vec3(x + 0.05f, 1.0f, 1.0f)));
    boxes.push_back(Aabb::from_corners(Vec3(100.0f + x, 0.0f, 0.0f), Vec3(100.05f + x, 1.0f, 1.0f)));
  }
  const Expected<BoxBvh> bvh = build_box_bvh(boxes, {.max_leaf_items = 10, .bins = 16});
  ASSERT_TRUE(bvh.ok());
  ASSERT_FALSE(bvh->nodes[0].is_leaf());
  const BvhNode& a = bvh->nodes[bvh->nodes[0].first];
  const BvhNode& b = bvh->nodes[bvh->nodes[0].first + 1];
  ASSERT_TRUE(a.is_leaf());
  ASSERT_TRUE(b.is_leaf());
  EXPECT_EQ(a.count, 10u);
  EXPECT_EQ(b.count, 10u);
  // Hand-checked: the near cluster's union and the far one's.
  EXPECT_TRUE(same_box(a.box, Aabb::from_corners(Vec3(0.0f), Vec3(9.0f * 0.1f + 0.05f, 1.0f, 1.0f))));
  EXPECT_EQ(b.box.lower.x, 100.0f);
  for (std::uint32_t i = a.first; i < a.first + a.count; ++i) EXPECT_EQ(bvh->items[i] % 2, 0u);
  EXPECT_TRUE(same_box(bvh->view().bounds, merge(a.box, b.box)));
}

TEST(BoxBvh, IdenticalCentresSplitAtTheMedianIntoSmallLeaves) {
  const std::vector<Aabb> boxes(1000, Aabb::from_corners(Vec3(-1.0f), Vec3(1.0f)));
  const BvhBuildOptions options{.max_leaf_items = 4, .bins = 16};
  const Expected<BoxBvh> bvh = build_box_bvh(boxes, options);
  ASSERT_TRUE(bvh.ok());
  check_tree(*bvh, boxes, options);
  EXPECT_LE(bvh->stats.max_depth, 9);  // halving 1000 to 4 or fewer
}

TEST(BoxBvh, AGeometricSeriesStaysWithinTheTraversalDepth) {
  // Every box in the first bin but one at each level: the SAH peels one box
  // a level, until kBvhSahDepth hands over to median splits.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 3000; ++i) {
    const float x = std::ldexp(1.0f, -(i % 120));
    boxes.push_back(Aabb::from_corners(Vec3(x, 0.0f, 0.0f), Vec3(x, 0.0f, 0.0f)));
  }
  const BvhBuildOptions options{.max_leaf_items = 1, .bins = 2};
  const Expected<BoxBvh> bvh = build_box_bvh(boxes, options);
  ASSERT_TRUE(bvh.ok());
  check_tree(*bvh, boxes, options);
  EXPECT_GT(bvh->stats.max_depth, 20);
  EXPECT_LE(bvh->stats.max_depth, kBvhSahDepth + 13);
}

TEST(BoxBvh, SameBoxesGiveTheSameTree) {
  std::mt19937 rng(3);
  const std::vector<Aabb> boxes = awkward_boxes(rng, 500);
  const Expected<BoxBvh> a = build_box_bvh(boxes), b = build_box_bvh(boxes);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->nodes.size(), b->nodes.size());
  EXPECT_EQ(a->items, b->items);
  for (std::size_t i = 0; i < a->nodes.size(); ++i) {
    EXPECT_TRUE(same_box(a->nodes[i].box, b->nodes[i].box));
    EXPECT_EQ(a->nodes[i].first, b->nodes[i].first);
    EXPECT_EQ(a->nodes[i].count, b->nodes[i].count);
  }
}

TEST(BoxBvh, BadBoxesAndOptionsAreRefusedNamingThem) {
  std::vector<Aabb> boxes(5, Aabb::from_corners(Vec3(0.0f), Vec3(1.0f)));
  boxes[3].upper.y = std::numeric_limits<float>::quiet_NaN();
  Expected<BoxBvh> bvh = build_box_bvh(boxes);
  ASSERT_FALSE(bvh.ok());
  EXPECT_EQ(bvh.status().code(), ErrorCode::kInvalidData);
  EXPECT_EQ(bvh.status().field(), "boxes[3]");
  boxes[3] = Aabb::from_corners(Vec3(0.0f), Vec3(1.0f));
  boxes[4].lower.x = -std::numeric_limits<float>::infinity();
  bvh = build_box_bvh(boxes);
  ASSERT_FALSE(bvh.ok());
  EXPECT_EQ(bvh.status().field(), "boxes[4]");
  boxes[4] = Aabb::empty();  // left out, not refused
  ASSERT_TRUE(build_box_bvh(boxes).ok());
  EXPECT_EQ(build_box_bvh(boxes)->items.size(), 4u);

  bvh = build_box_bvh(boxes, {.max_leaf_items = 0, .bins = 16});
  ASSERT_FALSE(bvh.ok());
  EXPECT_EQ(bvh.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(bvh.status().field(), "max_leaf_items");
  bvh = build_box_bvh(boxes, {.max_leaf_items = 4, .bins = 1});
  ASSERT_FALSE(bvh.ok());
  EXPECT_EQ(bvh.status().field(), "bins");
}

}  // namespace
}  // namespace sinew::rt
