// Tests of the SAH kd-tree builder against independent references: point
// descent and segment traversal written here, a brute-force O(N^2) SAH at the
// root, a walk of the tree for the stats, and hand-computed small trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "raytrace/accel/kd_tree.h"

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Uniform float in [0, 1) from 24 random bits (independent of the standard
// library's distributions, whose output is implementation-defined).
float unit(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }
int pick(std::mt19937& rng, int n) { return static_cast<int>(rng() % static_cast<std::uint32_t>(n)); }

// A box set with the awkward cases: coordinates on a coarse grid (shared
// faces), flat boxes, point boxes, duplicates, a few huge boxes.
std::vector<Aabb> awkward_boxes(std::mt19937& rng, int count) {
  std::vector<Aabb> boxes;
  auto grid = [&] { return static_cast<float>(pick(rng, 33)) * 0.25f - 4.0f; };
  for (int i = 0; i < count; ++i) {
    const int kind = pick(rng, 10);
    Aabb b;
    if (kind == 0 && !boxes.empty()) {
      b = boxes[static_cast<std::size_t>(pick(rng, static_cast<int>(boxes.size())))];  // duplicate
    } else if (kind == 1) {
      b = Aabb::from_point(Vec3(grid(), grid(), grid()));
    } else if (kind == 2 && pick(rng, 8) == 0) {
      b = Aabb::from_corners(Vec3(-6.0f + unit(rng), -5.0f, -7.0f), Vec3(5.0f, 6.0f - unit(rng), 4.0f));
    } else {
      b = Aabb::from_corners(Vec3(grid(), grid(), grid()), Vec3(grid(), grid(), grid()));
      if (kind >= 8) {  // random, off-grid small box
        const Vec3 lo(unit(rng) * 8.0f - 4.0f, unit(rng) * 8.0f - 4.0f, unit(rng) * 8.0f - 4.0f);
        b = Aabb::from_corners(lo, lo + Vec3(unit(rng), unit(rng), unit(rng)));
      }
      if (kind == 3 || kind == 4) {  // flat on one axis
        const int axis = pick(rng, 3);
        b.upper[axis] = b.lower[axis];
      }
    }
    boxes.push_back(b);
  }
  return boxes;
}

KdTree build_ok(std::span<const Aabb> boxes, const KdBuildOptions& options = {}) {
  Expected<KdTree> tree = build_kd_tree(boxes, options);
  EXPECT_TRUE(tree.ok()) << (tree.ok() ? "" : tree.status().message());
  return tree.ok() ? std::move(tree).value() : KdTree{};
}

// --- Independent walks of the tree -----------------------------------------

// Pre-order layout check: the below child follows its parent and the above
// child starts right after the below subtree. Returns the index after the
// subtree rooted at `index` (or nodes.size() + 1 on a broken layout).
std::size_t check_layout(const KdTreeView& t, std::size_t index) {
  if (index >= t.nodes.size()) return t.nodes.size() + 1;
  const KdNode& n = t.nodes[index];
  if (n.is_leaf()) {
    const std::size_t first = n.first_item();
    return first + n.item_count() <= t.items.size() ? index + 1 : t.nodes.size() + 1;
  }
  const std::size_t below_end = check_layout(t, index + 1);
  if (below_end != n.above_child()) return t.nodes.size() + 1;
  return check_layout(t, below_end);
}

double area_in_double(const Aabb& b) {
  const double x = static_cast<double>(b.upper.x) - static_cast<double>(b.lower.x);
  const double y = static_cast<double>(b.upper.y) - static_cast<double>(b.lower.y);
  const double z = static_cast<double>(b.upper.z) - static_cast<double>(b.lower.z);
  return 2.0 * (x * y + y * z + z * x);
}

struct WalkStats {
  std::uint32_t nodes = 0, leaves = 0, empty_leaves = 0, refs = 0;
  int max_depth = 0;
  double sah = 0.0;
};

void walk_stats(const KdTreeView& t, std::size_t index, const Aabb& cell, int depth, const KdBuildOptions& o,
                double root_area, WalkStats* s) {
  const KdNode& n = t.nodes[index];
  ++s->nodes;
  s->max_depth = std::max(s->max_depth, depth);
  const double area = area_in_double(cell);
  const double ratio = root_area > 0.0 ? area / root_area : 1.0;
  if (n.is_leaf()) {
    ++s->leaves;
    s->empty_leaves += n.item_count() == 0;
    s->refs += n.item_count();
    s->sah += static_cast<double>(o.intersection_cost) * n.item_count() * ratio;
    return;
  }
  s->sah += static_cast<double>(o.traversal_cost) * ratio;
  Aabb below = cell, above = cell;
  below.upper[n.axis()] = n.split();
  above.lower[n.axis()] = n.split();
  walk_stats(t, index + 1, below, depth + 1, o, root_area, s);
  walk_stats(t, n.above_child(), above, depth + 1, o, root_area, s);
}

// Every listed item is a valid index of a non-empty box that touches the
// leaf's cell (closed intervals), and every split lies inside its cell.
void check_cells(const KdTreeView& t, std::span<const Aabb> boxes, std::size_t index, const Aabb& cell) {
  const KdNode& n = t.nodes[index];
  if (n.is_leaf()) {
    for (std::uint32_t k = 0; k < n.item_count(); ++k) {
      const std::uint32_t item = t.items[n.first_item() + k];
      ASSERT_LT(item, boxes.size());
      const Aabb& b = boxes[item];
      ASSERT_FALSE(b.is_empty()) << item;
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(b.lower[a], cell.upper[a]) << "item " << item << " axis " << a;
        EXPECT_GE(b.upper[a], cell.lower[a]) << "item " << item << " axis " << a;
      }
    }
    return;
  }
  const int axis = n.axis();
  ASSERT_GE(n.split(), cell.lower[axis]);
  ASSERT_LE(n.split(), cell.upper[axis]);
  ASSERT_LT(cell.lower[axis], cell.upper[axis]) << "split along a flat axis";
  Aabb below = cell, above = cell;
  below.upper[axis] = n.split();
  above.lower[axis] = n.split();
  check_cells(t, boxes, index + 1, below);
  check_cells(t, boxes, n.above_child(), above);
}

// Descends to every leaf a point can be in: both sides when it lies on the
// split plane.
void descend_point(const KdTreeView& t, std::size_t index, const Vec3& p, std::vector<std::uint32_t>* items) {
  const KdNode& n = t.nodes[index];
  if (n.is_leaf()) {
    items->insert(items->end(), t.items.begin() + n.first_item(),
                  t.items.begin() + n.first_item() + n.item_count());
    return;
  }
  const float x = p[n.axis()];
  if (x <= n.split()) descend_point(t, index + 1, p, items);
  if (x >= n.split()) descend_point(t, n.above_child(), p, items);
}

bool point_finds(const KdTreeView& t, const Vec3& p, std::uint32_t item) {
  std::vector<std::uint32_t> items;
  descend_point(t, 0, p, &items);
  return std::find(items.begin(), items.end(), item) != items.end();
}

// Closed-interval segment/box overlap in double: t in [0, 1].
bool segment_hits(const Vec3& o, const Vec3& d, const Aabb& b) {
  double t0 = 0.0, t1 = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double oa = static_cast<double>(o[a]), da = static_cast<double>(d[a]);
    const double lo = static_cast<double>(b.lower[a]), hi = static_cast<double>(b.upper[a]);
    if (da == 0.0) {
      if (oa < lo || oa > hi) return false;
      continue;
    }
    double ta = (lo - oa) / da, tb = (hi - oa) / da;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// Collects the items of every leaf whose (closed) cell the segment touches.
void segment_leaves(const KdTreeView& t, std::size_t index, const Aabb& cell, const Vec3& o, const Vec3& d,
                    std::set<std::uint32_t>* items) {
  if (!segment_hits(o, d, cell)) return;
  const KdNode& n = t.nodes[index];
  if (n.is_leaf()) {
    items->insert(t.items.begin() + n.first_item(), t.items.begin() + n.first_item() + n.item_count());
    return;
  }
  Aabb below = cell, above = cell;
  below.upper[n.axis()] = n.split();
  above.lower[n.axis()] = n.split();
  segment_leaves(t, index + 1, below, o, d, items);
  segment_leaves(t, n.above_child(), above, o, d, items);
}

// Full structural check of a built tree over `boxes`.
void check_tree(const KdTree& tree, std::span<const Aabb> boxes, const KdBuildOptions& options) {
  const KdTreeView t = tree.view();
  Aabb bounds;
  std::uint32_t non_empty = 0;
  for (const Aabb& b : boxes) {
    if (b.is_empty()) continue;
    bounds.extend(b);
    ++non_empty;
  }
  if (non_empty == 0) {
    EXPECT_TRUE(t.empty());
    return;
  }
  ASSERT_FALSE(t.empty());
  EXPECT_EQ(t.bounds.lower, bounds.lower);
  EXPECT_EQ(t.bounds.upper, bounds.upper);
  ASSERT_EQ(check_layout(t, 0), t.nodes.size());
  check_cells(t, boxes, 0, bounds);

  WalkStats w;
  const double root_area = area_in_double(bounds);
  walk_stats(t, 0, bounds, 0, options, root_area, &w);
  EXPECT_EQ(tree.stats.node_count, w.nodes);
  EXPECT_EQ(tree.stats.node_count, t.nodes.size());
  EXPECT_EQ(tree.stats.leaf_count, w.leaves);
  EXPECT_EQ(tree.stats.empty_leaf_count, w.empty_leaves);
  EXPECT_EQ(tree.stats.item_refs, w.refs);
  EXPECT_EQ(tree.stats.item_refs, t.items.size());
  EXPECT_EQ(tree.stats.max_depth, w.max_depth);
  EXPECT_NEAR(tree.stats.sah_cost, w.sah, 1e-9 * w.sah);
  const std::uint32_t full = w.leaves - w.empty_leaves;
  EXPECT_DOUBLE_EQ(tree.stats.mean_items_per_leaf(), full ? static_cast<double>(w.refs) / full : 0.0);
}

// --- 1. Node encoding ------------------------------------------------------

TEST(KdBuilderNode, InnerRoundTripsSplitBitsAxisAndChild) {
  const float splits[] = {0.0f,
                          -0.0f,
                          1.0f,
                          -1.5f,
                          std::numeric_limits<float>::denorm_min(),
                          -std::numeric_limits<float>::denorm_min(),
                          1e-40f,
                          std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max()};
  const std::uint32_t children[] = {1u, 2u, 12345u, KdNode::kMaxIndex};
  for (int axis = 0; axis < 3; ++axis) {
    for (float s : splits) {
      for (std::uint32_t child : children) {
        const KdNode n = KdNode::inner(axis, s, child);
        EXPECT_FALSE(n.is_leaf());
        EXPECT_EQ(n.axis(), axis);
        EXPECT_EQ(std::bit_cast<std::uint32_t>(n.split()), std::bit_cast<std::uint32_t>(s));
        EXPECT_EQ(n.above_child(), child);
      }
    }
  }
}

TEST(KdBuilderNode, LeafRoundTripsFirstItemAndCount) {
  const std::uint32_t firsts[] = {0u, 7u, 0xffffffffu};
  const std::uint32_t counts[] = {0u, 1u, 1000u, KdNode::kMaxIndex};
  for (std::uint32_t first : firsts) {
    for (std::uint32_t count : counts) {
      const KdNode n = KdNode::leaf(first, count);
      EXPECT_TRUE(n.is_leaf());
      EXPECT_EQ(n.first_item(), first);
      EXPECT_EQ(n.item_count(), count);
    }
  }
  EXPECT_TRUE(KdNode{}.is_leaf());
}

// --- 2. Containment --------------------------------------------------------

TEST(KdBuilderContainment, EveryPointOfEveryBoxReachesALeafListingIt) {
  std::mt19937 rng(20061);
  const int sizes[] = {1, 2, 3, 5, 9, 17, 40, 100, 333, 2000};
  for (int size : sizes) {
    for (int round = 0; round < 2; ++round) {
      const std::vector<Aabb> boxes = awkward_boxes(rng, size);
      KdBuildOptions options;
      options.max_leaf_items = 1 + round;
      const KdTree tree = build_ok(boxes, options);
      check_tree(tree, boxes, options);
      const KdTreeView t = tree.view();
      for (std::uint32_t i = 0; i < boxes.size(); ++i) {
        const Aabb& b = boxes[i];
        std::vector<Vec3> points;
        for (int c = 0; c < 8; ++c)
          points.emplace_back(c & 1 ? b.upper.x : b.lower.x, c & 2 ? b.upper.y : b.lower.y,
                              c & 4 ? b.upper.z : b.lower.z);
        for (int k = 0; k < 4; ++k) {
          const Vec3 inside = glm::mix(b.lower, b.upper, Vec3(unit(rng), unit(rng), unit(rng)));
          points.push_back(inside);
          Vec3 on_face = inside;
          const int axis = pick(rng, 3);
          on_face[axis] = (k & 1) ? b.upper[axis] : b.lower[axis];
          points.push_back(on_face);
        }
        points.push_back(b.center());
        for (const Vec3& p : points) {
          ASSERT_TRUE(b.contains(p));
          ASSERT_TRUE(point_finds(t, p, i)) << "size " << size << " box " << i << " point " << p.x << ","
                                            << p.y << "," << p.z;
        }
      }
    }
  }
}

// --- 3. SAH quality at the root against a brute-force reference ------------

// Cost of splitting `cell` holding `boxes` at (axis, p) with the planar boxes
// on the given side; negative when the builder's rules forbid the candidate.
double reference_cost(std::span<const Aabb> boxes, const Aabb& cell, int axis, float p, bool planar_below,
                      const KdBuildOptions& o) {
  const float lo = cell.lower[axis], hi = cell.upper[axis];
  if (!(lo < hi) || p < lo || p > hi) return -1.0;
  int nb = 0, na = 0, np = 0;
  for (const Aabb& b : boxes) {
    const float l = b.lower[axis], u = b.upper[axis];
    if (l == u && l == p) {
      ++np;
      (planar_below ? nb : na) += 1;
    } else if (u <= p) {
      ++nb;
    } else if (l >= p) {
      ++na;
    } else {
      ++nb;
      ++na;
    }
  }
  const bool inside = lo < p && p < hi;
  if (!inside && !(np > 0 && (planar_below ? p == lo : p == hi))) return -1.0;
  auto area = [](double x, double y, double z) { return 2.0 * (x * y + y * z + z * x); };
  double e[3];
  for (int a = 0; a < 3; ++a) e[a] = static_cast<double>(cell.upper[a]) - static_cast<double>(cell.lower[a]);
  const double total = area(e[0], e[1], e[2]);
  double eb[3] = {e[0], e[1], e[2]}, ea[3] = {e[0], e[1], e[2]};
  eb[axis] = static_cast<double>(p) - static_cast<double>(lo);
  ea[axis] = static_cast<double>(hi) - static_cast<double>(p);
  const bool bonus = (nb == 0 && p > lo) || (na == 0 && p < hi);
  const double lambda = bonus ? 1.0 - static_cast<double>(o.empty_bonus) : 1.0;
  return static_cast<double>(o.traversal_cost) +
         static_cast<double>(o.intersection_cost) * lambda *
             (area(eb[0], eb[1], eb[2]) * nb + area(ea[0], ea[1], ea[2]) * na) / total;
}

double reference_best_cost(std::span<const Aabb> boxes, const Aabb& cell, const KdBuildOptions& o) {
  double best = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    for (const Aabb& b : boxes) {
      for (float p : {b.lower[axis], b.upper[axis]}) {
        for (bool side : {true, false}) {
          const double c = reference_cost(boxes, cell, axis, p, side, o);
          if (c >= 0.0) best = std::min(best, c);
        }
      }
    }
  }
  return best;
}

// The node's items are the union of its subtree's leaf items; their boxes,
// clipped to the node's cell, are what the builder swept at that node.
void subtree_items(const KdTreeView& t, std::size_t index, std::set<std::uint32_t>* items) {
  const KdNode& n = t.nodes[index];
  if (n.is_leaf()) {
    items->insert(t.items.begin() + n.first_item(), t.items.begin() + n.first_item() + n.item_count());
    return;
  }
  subtree_items(t, index + 1, items);
  subtree_items(t, n.above_child(), items);
}

double split_cost_of_node(std::span<const Aabb> boxes, const Aabb& cell, const KdNode& n, const KdBuildOptions& o) {
  double got = std::numeric_limits<double>::infinity();
  for (bool side : {true, false}) {
    const double c = reference_cost(boxes, cell, n.axis(), n.split(), side, o);
    if (c >= 0.0) got = std::min(got, c);
  }
  return got;
}

struct SahCheck {
  int splits = 0;
  int leaves_by_cost = 0;
};

// At every node that the termination rules let split, the builder's choice
// costs what the brute-force minimum costs, and a leaf is chosen exactly when
// no split beats intersection_cost * N.
void check_sah_everywhere(const KdTreeView& t, std::span<const Aabb> all, std::size_t index, const Aabb& cell,
                          int depth, const KdBuildOptions& o, SahCheck* out) {
  std::set<std::uint32_t> items;
  subtree_items(t, index, &items);
  std::vector<Aabb> clipped;
  for (std::uint32_t i : items) clipped.push_back(intersection(all[i], cell));
  const KdNode& n = t.nodes[index];
  const double n_items = static_cast<double>(clipped.size());
  const bool may_split = clipped.size() > static_cast<std::size_t>(o.max_leaf_items) && depth < o.max_depth &&
                         cell.surface_area() > 0.0f;
  if (may_split) {
    const double best = reference_best_cost(clipped, cell, o);
    const double leaf_cost = static_cast<double>(o.intersection_cost) * n_items;
    if (n.is_leaf()) {
      EXPECT_GE(best, leaf_cost * (1.0 - 1e-6)) << "node " << index;
      ++out->leaves_by_cost;
    } else {
      EXPECT_NEAR(split_cost_of_node(clipped, cell, n, o), best, 1e-5 * best) << "node " << index;
      EXPECT_LT(best, leaf_cost * (1.0 + 1e-6)) << "node " << index;
      ++out->splits;
    }
  } else {
    EXPECT_TRUE(n.is_leaf()) << "node " << index;
  }
  if (n.is_leaf()) return;
  Aabb below = cell, above = cell;
  below.upper[n.axis()] = n.split();
  above.lower[n.axis()] = n.split();
  check_sah_everywhere(t, all, index + 1, below, depth + 1, o, out);
  check_sah_everywhere(t, all, n.above_child(), above, depth + 1, o, out);
}

TEST(KdBuilderSah, EveryNodeMatchesBruteForceMinimum) {
  std::mt19937 rng(4242);
  SahCheck total;
  for (int round = 0; round < 100; ++round) {
    const int size = 8 + pick(rng, 57);
    std::vector<Aabb> boxes = awkward_boxes(rng, size);
    KdBuildOptions options;
    options.traversal_cost = 0.3f + unit(rng);
    options.intersection_cost = 0.5f + unit(rng) * 2.0f;
    options.empty_bonus = (round % 3 == 0) ? 0.0f : unit(rng) * 0.9f;
    options.max_leaf_items = 1 + round % 3;
    options.max_depth = 12;
    const KdTree tree = build_ok(boxes, options);
    ASSERT_FALSE(tree.nodes.empty());
    check_sah_everywhere(tree.view(), boxes, 0, tree.bounds, 0, options, &total);
  }
  EXPECT_GT(total.splits, 500);
  EXPECT_GT(total.leaves_by_cost, 100);
}

// Two unit cubes, [0,1]^3 and [2,3]x[0,1]^2: the root cell has area 14; the
// splits x=1 and x=2 tie at 1 + 1.5 (6 + 10) / 14; the lower position wins.
TEST(KdBuilderSah, TwoCubesHandComputed) {
  const std::vector<Aabb> boxes = {Aabb::from_corners(Vec3(0.0f), Vec3(1.0f)),
                                   Aabb::from_corners(Vec3(2.0f, 0.0f, 0.0f), Vec3(3.0f, 1.0f, 1.0f))};
  const KdTree tree = build_ok(boxes);
  ASSERT_EQ(tree.nodes.size(), 3u);
  EXPECT_EQ(tree.nodes[0].axis(), 0);
  EXPECT_EQ(tree.nodes[0].split(), 1.0f);
  EXPECT_EQ(tree.nodes[0].above_child(), 2u);
  ASSERT_TRUE(tree.nodes[1].is_leaf());
  ASSERT_TRUE(tree.nodes[2].is_leaf());
  EXPECT_EQ(tree.items, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(tree.nodes[1].first_item(), 0u);
  EXPECT_EQ(tree.nodes[2].first_item(), 1u);
  EXPECT_NEAR(tree.stats.sah_cost, 1.0 + 1.5 * 16.0 / 14.0, 1e-12);

  // Traversal cost 2 makes the split (3.714) dearer than the leaf (3).
  KdBuildOptions dear;
  dear.traversal_cost = 2.0f;
  const KdTree leaf = build_ok(boxes, dear);
  ASSERT_EQ(leaf.nodes.size(), 1u);
  EXPECT_TRUE(leaf.nodes[0].is_leaf());
  EXPECT_EQ(leaf.nodes[0].item_count(), 2u);
  EXPECT_NEAR(leaf.stats.sah_cost, 3.0, 1e-12);
}

// Twenty squares lying in the plane x=0 and one box [0,10]x[0,1]^2: the only
// allowed split is on the cell face x=0 with the planar squares below
// (area 2 of 42): cost 1 + 1.5 (2/42 * 20 + 1) against 1.5 * 21.
TEST(KdBuilderSah, CutsOffPlanarBoxesOnTheCellFace) {
  std::vector<Aabb> boxes(20, Aabb::from_corners(Vec3(0.0f), Vec3(0.0f, 1.0f, 1.0f)));
  boxes.push_back(Aabb::from_corners(Vec3(0.0f), Vec3(10.0f, 1.0f, 1.0f)));
  const KdTree tree = build_ok(boxes);
  ASSERT_EQ(tree.nodes.size(), 3u);
  EXPECT_EQ(tree.nodes[0].axis(), 0);
  EXPECT_EQ(tree.nodes[0].split(), 0.0f);
  EXPECT_EQ(tree.nodes[1].item_count(), 20u);
  EXPECT_EQ(tree.nodes[2].item_count(), 1u);
  EXPECT_EQ(tree.items[tree.nodes[2].first_item()], 20u);
  EXPECT_NEAR(tree.stats.sah_cost, 1.0 + 1.5 * (2.0 / 42.0 * 20.0 + 1.0), 1e-9);
  check_tree(tree, boxes, {});
}

// The mirror image: squares in the plane x=10 are cut off above.
TEST(KdBuilderSah, CutsOffPlanarBoxesOnTheUpperCellFace) {
  std::vector<Aabb> boxes = {Aabb::from_corners(Vec3(0.0f), Vec3(10.0f, 1.0f, 1.0f))};
  boxes.resize(21, Aabb::from_corners(Vec3(10.0f, 0.0f, 0.0f), Vec3(10.0f, 1.0f, 1.0f)));
  const KdTree tree = build_ok(boxes);
  ASSERT_EQ(tree.nodes.size(), 3u);
  EXPECT_EQ(tree.nodes[0].axis(), 0);
  EXPECT_EQ(tree.nodes[0].split(), 10.0f);
  EXPECT_EQ(tree.nodes[1].item_count(), 1u);
  EXPECT_EQ(tree.items[tree.nodes[1].first_item()], 0u);
  EXPECT_EQ(tree.nodes[2].item_count(), 20u);
  check_tree(tree, boxes, {});
}

// --- 4. Termination --------------------------------------------------------

TEST(KdBuilderTermination, FewItemsMakeOneLeaf) {
  std::mt19937 rng(7);
  const std::vector<Aabb> boxes = awkward_boxes(rng, 10);
  KdBuildOptions options;
  options.max_leaf_items = 10;
  const KdTree tree = build_ok(boxes, options);
  ASSERT_EQ(tree.nodes.size(), 1u);
  ASSERT_TRUE(tree.nodes[0].is_leaf());
  std::vector<std::uint32_t> expected;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    if (!boxes[i].is_empty()) expected.push_back(i);
  EXPECT_EQ(tree.items, expected);
  check_tree(tree, boxes, options);
}

TEST(KdBuilderTermination, DepthLimitIsRespected) {
  std::mt19937 rng(8);
  const std::vector<Aabb> boxes = awkward_boxes(rng, 1000);
  for (int depth : {1, 3, 6}) {
    KdBuildOptions options;
    options.max_depth = depth;
    const KdTree tree = build_ok(boxes, options);
    EXPECT_EQ(tree.stats.max_depth, depth);  // 1000 boxes always want more depth
    check_tree(tree, boxes, options);
  }
  const KdTree automatic = build_ok(boxes);
  const int rule = static_cast<int>(std::lround(8.0 + 1.3 * std::log2(1000.0)));  // 21
  EXPECT_LE(automatic.stats.max_depth, rule);
  EXPECT_GT(automatic.stats.max_depth, 6);
  check_tree(automatic, boxes, {});
}

TEST(KdBuilderTermination, IdenticalBoxesMakeOneLeaf) {
  const std::vector<Aabb> cubes(500, Aabb::from_corners(Vec3(-1.0f), Vec3(2.0f)));
  const KdTree tree = build_ok(cubes);
  ASSERT_EQ(tree.nodes.size(), 1u);
  EXPECT_EQ(tree.nodes[0].item_count(), 500u);

  const std::vector<Aabb> points(300, Aabb::from_point(Vec3(1.0f, 2.0f, 3.0f)));
  const KdTree point_tree = build_ok(points);
  ASSERT_EQ(point_tree.nodes.size(), 1u);
  EXPECT_EQ(point_tree.nodes[0].item_count(), 300u);
  EXPECT_DOUBLE_EQ(point_tree.stats.sah_cost, 1.5 * 300.0);  // zero-area root: intersection_cost * N
}

TEST(KdBuilderTermination, BoxesFlatInOnePlaneNeverSplitTheFlatAxis) {
  std::mt19937 rng(9);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 400; ++i) {
    const Vec3 lo(unit(rng) * 10.0f, 3.0f, unit(rng) * 10.0f);
    boxes.push_back(Aabb::from_corners(lo, lo + Vec3(unit(rng), 0.0f, unit(rng))));
  }
  const KdTree tree = build_ok(boxes);
  EXPECT_GT(tree.nodes.size(), 50u);
  for (const KdNode& n : tree.nodes) {
    if (!n.is_leaf()) {
      EXPECT_NE(n.axis(), 1);
    }
  }
  check_tree(tree, boxes, {});  // also checks no split along a flat cell axis
  for (std::uint32_t i = 0; i < boxes.size(); ++i) ASSERT_TRUE(point_finds(tree.view(), boxes[i].center(), i));
}

// Boxes near the float range: the areas would overflow in float.
TEST(KdBuilderTermination, HugeCoordinatesStillBuildASensibleTree) {
  std::mt19937 rng(11);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 300; ++i) {
    const Vec3 lo(unit(rng) * 6e37f - 3e37f, unit(rng) * 6e37f - 3e37f, unit(rng) * 6e37f - 3e37f);
    boxes.push_back(Aabb::from_corners(lo, lo + Vec3(unit(rng), unit(rng), unit(rng)) * 1e36f));
  }
  boxes.push_back(Aabb::from_corners(Vec3(-3.4e38f), Vec3(3.4e38f)));
  const KdTree tree = build_ok(boxes);
  EXPECT_GT(tree.nodes.size(), 100u);
  EXPECT_LT(tree.stats.max_depth, 30);
  EXPECT_TRUE(std::isfinite(tree.stats.sah_cost));
  check_tree(tree, boxes, {});
  for (std::uint32_t i = 0; i < boxes.size(); ++i) ASSERT_TRUE(point_finds(tree.view(), boxes[i].center(), i));
}

// --- 5. Determinism, errors, empty input -----------------------------------

TEST(KdBuilderDeterminism, SameInputSameTree) {
  std::mt19937 rng(10);
  const std::vector<Aabb> boxes = awkward_boxes(rng, 1500);
  const KdTree a = build_ok(boxes);
  const KdTree b = build_ok(boxes);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].word0, b.nodes[i].word0);
    EXPECT_EQ(a.nodes[i].word1, b.nodes[i].word1);
  }
  EXPECT_EQ(a.items, b.items);
  EXPECT_EQ(a.stats.sah_cost, b.stats.sah_cost);
}

TEST(KdBuilderErrors, NonFiniteBoxesNameTheirIndex) {
  std::vector<Aabb> boxes(5, Aabb::from_corners(Vec3(0.0f), Vec3(1.0f)));
  boxes[1] = Aabb::empty();  // skipped, not an error
  boxes[3].upper.y = std::nanf("");
  Expected<KdTree> r = build_kd_tree(boxes);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidData);
  EXPECT_EQ(r.status().field(), "boxes[3]");
  EXPECT_NE(r.status().value().find("nan"), std::string_view::npos) << r.status().message();

  boxes[3] = Aabb::from_corners(Vec3(0.0f), Vec3(1.0f));
  boxes[4].lower.z = -kInf;
  r = build_kd_tree(boxes);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidData);
  EXPECT_EQ(r.status().field(), "boxes[4]");
  EXPECT_NE(r.status().value().find("inf"), std::string_view::npos) << r.status().message();

  boxes[4] = Aabb::from_corners(Vec3(0.0f), Vec3(1.0f));
  boxes[0].lower.x = std::nanf("");  // NaN lower with a greater upper is not "empty"
  boxes[0].upper.x = -kInf;
  r = build_kd_tree(boxes);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().field(), "boxes[0]");
}

TEST(KdBuilderErrors, BadOptionsNameTheOption) {
  const std::vector<Aabb> boxes(3, Aabb::from_corners(Vec3(0.0f), Vec3(1.0f)));
  struct Case {
    KdBuildOptions options;
    const char* field;
  };
  std::vector<Case> cases;
  auto add = [&](const char* field, auto mutate) {
    KdBuildOptions o;
    mutate(o);
    cases.push_back({o, field});
  };
  add("options.traversal_cost", [](KdBuildOptions& o) { o.traversal_cost = -1.0f; });
  add("options.traversal_cost", [](KdBuildOptions& o) { o.traversal_cost = std::nanf(""); });
  add("options.intersection_cost", [](KdBuildOptions& o) { o.intersection_cost = -0.5f; });
  add("options.intersection_cost", [](KdBuildOptions& o) { o.intersection_cost = kInf; });
  add("options.empty_bonus", [](KdBuildOptions& o) { o.empty_bonus = 1.0f; });
  add("options.empty_bonus", [](KdBuildOptions& o) { o.empty_bonus = -0.1f; });
  add("options.empty_bonus", [](KdBuildOptions& o) { o.empty_bonus = std::nanf(""); });
  add("options.max_leaf_items", [](KdBuildOptions& o) { o.max_leaf_items = 0; });
  add("options.max_depth", [](KdBuildOptions& o) { o.max_depth = -1; });
  for (const Case& c : cases) {
    Expected<KdTree> r = build_kd_tree(boxes, c.options);
    ASSERT_FALSE(r.ok()) << c.field;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(r.status().field(), c.field);
    EXPECT_FALSE(r.status().value().empty());
  }
  KdBuildOptions edge;
  edge.traversal_cost = 0.0f;
  edge.intersection_cost = 0.0f;
  edge.empty_bonus = 0.0f;
  EXPECT_TRUE(build_kd_tree(boxes, edge).ok());
}

TEST(KdBuilderEmpty, NoNonEmptyBoxesGiveATreeWithoutNodes) {
  const KdTree none = build_ok({});
  EXPECT_TRUE(none.view().empty());
  EXPECT_TRUE(none.items.empty());
  EXPECT_TRUE(none.bounds.is_empty());
  EXPECT_EQ(none.stats.node_count, 0u);
  EXPECT_EQ(none.stats.sah_cost, 0.0);

  const std::vector<Aabb> empties = {Aabb::empty(), Aabb::from_corners(Vec3(0.0f), Vec3(1.0f))};
  std::vector<Aabb> inverted = empties;
  inverted[1].lower.y = 2.0f;  // lower > upper: empty as well
  const KdTree all_empty = build_ok(inverted);
  EXPECT_TRUE(all_empty.view().empty());
  EXPECT_TRUE(all_empty.bounds.is_empty());

  const KdTree one = build_ok(empties);  // the empty box is left out
  ASSERT_EQ(one.nodes.size(), 1u);
  EXPECT_EQ(one.items, std::vector<std::uint32_t>{1});
}

// --- 6. Segment queries over triangle boxes --------------------------------

TEST(KdBuilderRays, SegmentsFindTheSameBoxesAsBruteForce) {
  std::mt19937 rng(2006);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 a(unit(rng) * 20.0f - 10.0f, unit(rng) * 20.0f - 10.0f, unit(rng) * 20.0f - 10.0f);
    Aabb b = Aabb::from_point(a);
    for (int v = 0; v < 2; ++v)
      b.extend(a + Vec3(unit(rng) * 2.0f - 1.0f, unit(rng) * 2.0f - 1.0f, unit(rng) * 2.0f - 1.0f));
    if (i % 7 == 0) b.upper.z = b.lower.z;  // axis-aligned triangles give flat boxes
    boxes.push_back(b);
  }
  const KdTree tree = build_ok(boxes);
  check_tree(tree, boxes, {});
  const KdTreeView t = tree.view();

  // Split positions of inner nodes: origins exactly on split planes.
  std::vector<std::pair<int, float>> planes;
  for (const KdNode& n : tree.nodes)
    if (!n.is_leaf()) planes.emplace_back(n.axis(), n.split());
  ASSERT_FALSE(planes.empty());

  auto random_point = [&] {
    return Vec3(unit(rng) * 24.0f - 12.0f, unit(rng) * 24.0f - 12.0f, unit(rng) * 24.0f - 12.0f);
  };
  int hits_total = 0;
  for (int r = 0; r < 600; ++r) {
    Vec3 o = random_point();
    Vec3 d = random_point() - o;
    if (r % 3 == 1) {  // axis-parallel
      const int axis = pick(rng, 3);
      const float len = d[axis];
      d = Vec3(0.0f);
      d[axis] = len;
    }
    if (r % 2 == 0) {  // origin on a split plane
      const auto& [axis, split] = planes[static_cast<std::size_t>(pick(rng, static_cast<int>(planes.size())))];
      o[axis] = split;
      if (r % 4 == 0) d[axis] = 0.0f;  // and running inside it
    }
    std::set<std::uint32_t> candidates;
    segment_leaves(t, 0, tree.bounds, o, d, &candidates);
    std::set<std::uint32_t> found, expected;
    for (std::uint32_t i : candidates)
      if (segment_hits(o, d, boxes[i])) found.insert(i);
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
      if (segment_hits(o, d, boxes[i])) expected.insert(i);
    ASSERT_EQ(found, expected) << "ray " << r;
    hits_total += static_cast<int>(expected.size());
  }
  EXPECT_GT(hits_total, 600);  // the rays do hit things
}

}  // namespace
}  // namespace sinew::rt
