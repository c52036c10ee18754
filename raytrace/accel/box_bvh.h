// BoxBvh: a binary bounding-volume hierarchy over boxes, the second bone-tree
// structure beside the fuzzy kd-tree (raytrace/accel/kd_tree.h; chosen by
// FuzzyBakeOptions::bone_trees, docs/RAYTRACE.md "Bone trees: kd-tree or
// BVH").
//
// Where the kd-tree splits space and lists a straddling box in every cell it
// overlaps, a BVH splits the boxes: each is listed exactly once, and a node's
// box is the union of its boxes. A fuzzy box near a joint is large, so on a
// finely subdivided mesh the kd-tree's leaves fill with the same fat boxes
// again and again; the BVH's do not, at the price of sibling boxes that may
// overlap (a walk enters both).
//
// Layout: 32-byte nodes; the root is nodes[0]; an inner node's children are
// adjacent (nodes[first] and nodes[first + 1]) and come after it; a leaf
// lists `count` items from items[first], increasing. Indices are relative to
// the tree's own arrays, so trees concatenate (a pack, a character's bones)
// by slicing spans, as kd-trees do.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/math/aabb.h"

namespace sinew::rt {

struct BvhNode {
  Aabb box;                 // the union of the boxes below
  std::uint32_t first = 0;  // inner: the first child (the second follows it); leaf: the first item
  std::uint32_t count = 0;  // leaf: its item count (at least 1); inner: 0

  bool is_leaf() const { return count != 0; }
};
static_assert(sizeof(BvhNode) == 32);

// A tree in place: spans over a BoxBvh's vectors or over a mapped pack. An
// empty tree has no nodes. Items are indices of the boxes it was built over.
struct BvhView {
  std::span<const BvhNode> nodes;
  std::span<const std::uint32_t> items;
  Aabb bounds;  // the root's box
  bool empty() const { return nodes.empty(); }
};

struct BvhBuildOptions {
  // A node with this many boxes or fewer becomes a leaf. Large packets test
  // a leaf's triangles against each group's frustum first, so their leaves
  // pay at sizes a single ray would not (docs/BENCHMARKS.md, the BVH leaf
  // sizes).
  int max_leaf_items = 32;
  // SAH bins per axis over the box centres.
  int bins = 16;
};

struct BvhStats {
  std::uint32_t node_count = 0;
  std::uint32_t leaf_count = 0;
  std::uint32_t item_count = 0;
  int max_depth = 0;  // root = 0
  double mean_items_per_leaf() const { return leaf_count ? static_cast<double>(item_count) / leaf_count : 0.0; }
};

struct BoxBvh {
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> items;
  BvhStats stats;

  BvhView view() const { return {nodes, items, nodes.empty() ? Aabb::empty() : nodes.front().box}; }
};

// The deepest a build goes: from here it splits at the median, so a tree over
// 2^32 boxes stays within the traversal's kMaxTraversalDepth (96).
inline constexpr int kBvhSahDepth = 60;

// kInvalidArgument naming the option when `options` cannot build a tree
// (a leaf of fewer than 1 item, bins outside [2, 256]); what
// build_box_bvh checks first, for callers that check before costly work.
Status check_bvh_options(const BvhBuildOptions& options);

// Builds a BVH over the non-empty `boxes` by binned SAH on their centres
// (median split where the centres do not separate or past kBvhSahDepth).
// Empty boxes (Aabb::empty()) are left out; none left: no nodes.
// Deterministic: the same boxes and options give the same tree. Errors:
// kInvalidData naming the first non-finite box ("boxes[i]"),
// kInvalidArgument for bad options, kLimitExceeded past 2^31 boxes.
Expected<BoxBvh> build_box_bvh(std::span<const Aabb> boxes, const BvhBuildOptions& options = {});

}  // namespace sinew::rt
