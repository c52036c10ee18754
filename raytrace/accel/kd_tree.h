// KdTree: the one kd-tree layout Sinew traverses, for the per-bone fuzzy
// kd-trees (over fuzzy boxes in a bone's frame, paper section 3.4), the static
// kd-tree (over static triangles) and the per-frame top-level tree (over bone
// world boxes).
//
// Nodes are 8 bytes (Wald's layout, as in pbrt): a float split or a leaf's
// first item, and one word packing the axis (or the leaf tag) with the above
// child's index or the leaf's item count. The below child always follows its
// parent, so descending into it touches the next node in memory. Indices are
// relative to the tree's own node and item arrays, so trees can be
// concatenated in one array (a pack, a character's bones) by slicing spans.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/math/aabb.h"

namespace sinew::rt {

struct KdNode {
  std::uint32_t word0 = 0;  // inner: the split's float bits; leaf: first item index
  std::uint32_t word1 = 3;  // bits 0-1: axis 0..2 or 3 = leaf; bits 2-31: above child or item count

  static constexpr std::uint32_t kLeafTag = 3;
  static constexpr std::uint32_t kMaxIndex = (1u << 30) - 1;  // node index or item count

  static KdNode inner(int axis, float split, std::uint32_t above_child) {
    return {std::bit_cast<std::uint32_t>(split), (above_child << 2) | static_cast<std::uint32_t>(axis)};
  }
  static KdNode leaf(std::uint32_t first_item, std::uint32_t item_count) {
    return {first_item, (item_count << 2) | kLeafTag};
  }

  bool is_leaf() const { return (word1 & 3u) == kLeafTag; }
  int axis() const { return static_cast<int>(word1 & 3u); }  // inner nodes only
  float split() const { return std::bit_cast<float>(word0); }
  std::uint32_t above_child() const { return word1 >> 2; }  // below child = this index + 1
  std::uint32_t first_item() const { return word0; }
  std::uint32_t item_count() const { return word1 >> 2; }
};
static_assert(sizeof(KdNode) == 8);

// A tree in place: spans over a KdTree's vectors or over a mapped pack. The
// root is nodes[0]; an empty tree has no nodes. Items are the indices of the
// primitives (boxes) the tree was built over.
struct KdTreeView {
  std::span<const KdNode> nodes;
  std::span<const std::uint32_t> items;
  Aabb bounds;  // the root cell: the union of the (non-empty) input boxes
  bool empty() const { return nodes.empty(); }
};

// The deepest tree the traversal's fixed stack supports (root = depth 0).
// Trees built by the scene are capped to it; loaded trees are checked. The
// automatic depth limit stays far below (47 for 2^30 boxes).
inline constexpr int kMaxTraversalDepth = 96;

struct KdBuildOptions {
  // Surface area heuristic: cost(split) = traversal_cost + intersection_cost *
  // (SA_below/SA * N_below + SA_above/SA * N_above) * (1 - empty_bonus when a
  // side is empty). A node becomes a leaf when no split beats
  // intersection_cost * N.
  float traversal_cost = 1.0f;
  float intersection_cost = 1.5f;
  float empty_bonus = 0.2f;  // in [0, 1)
  int max_leaf_items = 1;    // never split a node with this many items or fewer
  int max_depth = 0;         // 0: automatic, round(8 + 1.3 log2 N) (pbrt's rule)
};

struct KdTreeStats {
  std::uint32_t node_count = 0;
  std::uint32_t leaf_count = 0;
  std::uint32_t empty_leaf_count = 0;
  std::uint32_t item_refs = 0;  // sum of leaf item counts (a straddling box counts once per leaf)
  int max_depth = 0;            // root = 0
  double sah_cost = 0.0;        // the expected cost of a random ray through the root, per the options
  // Items per non-empty leaf, the paper's "triangles per leaf".
  double mean_items_per_leaf() const {
    const std::uint32_t full = leaf_count - empty_leaf_count;
    return full ? static_cast<double>(item_refs) / full : 0.0;
  }
};

struct KdTree {
  std::vector<KdNode> nodes;
  std::vector<std::uint32_t> items;
  Aabb bounds;
  KdTreeStats stats;

  KdTreeView view() const { return {nodes, items, bounds}; }
};

// Builds an SAH kd-tree over `boxes` with the O(N log N) sweep of Wald and
// Havran 2006 (events sorted once; no per-node re-sorting): boxes that
// straddle a split are clipped to each child's cell; flat boxes (zero width on
// an axis) are handled as planar events; empty boxes (Aabb::empty()) are left
// out of the tree. Deterministic: the same boxes and options give the same
// tree. Errors: kInvalidData naming the first non-finite box ("boxes[i]"),
// kInvalidArgument for bad options, kLimitExceeded past KdNode::kMaxIndex.
Expected<KdTree> build_kd_tree(std::span<const Aabb> boxes, const KdBuildOptions& options = {});

}  // namespace sinew::rt
