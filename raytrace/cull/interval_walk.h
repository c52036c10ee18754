// The walks of a ray set's interval bound (cull/interval_bound.h): front to
// back over the cells of a kd-tree, or the nodes of a BVH, that the bound
// reaches, one box test per cell whatever the number of rays. The packet
// core walks bone and world trees with them (traverse/large_packet.cpp),
// the tile culls the top level and static meshes (cull/ray_bound.cpp,
// cull/static_tiles.cpp). The single ray keeps its own stack walk
// (traverse/traversal.cpp): one ray needs no bound.
//
// Both walks read the limit (`limit()`: the largest t any ray still looks
// for) whenever they pop a cell, since a leaf's hits lower it.
// `leaf(cell, node, items)` returns true to stop.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>

#include "raytrace/accel/box_bvh.h"
#include "raytrace/accel/kd_tree.h"
#include "raytrace/cull/interval_bound.h"

namespace sinew::rt {

// A kd-tree cell waiting on the stack, with the parameter range that
// holds every ray's passage through it.
// Plain arrays: glm's operator[] is a switch on the index.
struct Cell {
  float lo[3], hi[3];
  std::uint32_t node;
  float t0, t1;
  Aabb box() const { return {Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2])}; }
};

// Each cell with a parameter range [t0, t1] that holds every ray's passage
// through it: on a split axis where every ray has one sign, the child
// ranges are cut at the bounds on where the rays cross the (thick) split
// plane, one product pair per node; elsewhere each child box is tested
// whole. Cells are grown by `grow` (IntervalBound::grow_for).
template <class Limit, class Leaf>
void interval_walk(const KdTreeView& tree, const IntervalBound& bound, const IntervalBound::Growth& grow,
                   Limit& limit, Leaf&& leaf, std::uint64_t& node_visits) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::array<Cell, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  Cell cur{{tree.bounds.lower.x, tree.bounds.lower.y, tree.bounds.lower.z},
           {tree.bounds.upper.x, tree.bounds.upper.y, tree.bounds.upper.z},
           0,
           bound.entry(tree.bounds, grow, limit()),
           bound.t_hi()};
  if (cur.t0 == kInf) return;
  for (;;) {
    cur.t1 = std::min(cur.t1, limit());
    if (cur.t0 <= cur.t1) {
      ++node_visits;
      const KdNode node = tree.nodes[cur.node];
      if (!node.is_leaf()) {
        const int a = node.axis();
        const float split = node.split();
        Cell below = cur, above = cur;
        below.node = cur.node + 1;
        above.node = node.above_child();
        below.hi[a] = std::min(below.hi[a], split);
        above.lo[a] = std::max(above.lo[a], split);
        const int sign = bound.sign(a);
        bool below_first = true;
        if (sign > 0) {
          // Rising rays: below until they cross split + grow, above from split - grow.
          below.t1 = std::min(cur.t1, bound.crossing_hi(a, split + grow.axis[a]));
          above.t0 = std::max(cur.t0, bound.crossing_lo(a, split - grow.axis[a]));
        } else if (sign < 0) {
          above.t1 = std::min(cur.t1, bound.crossing_hi(a, split - grow.axis[a]));
          below.t0 = std::max(cur.t0, bound.crossing_lo(a, split + grow.axis[a]));
          below_first = false;
        } else {
          const float eb = bound.entry(below.box(), grow, cur.t1);
          const float ea = bound.entry(above.box(), grow, cur.t1);
          below.t0 = std::max(cur.t0, eb);
          above.t0 = std::max(cur.t0, ea);
          if (eb == kInf) below.t0 = kInf;
          if (ea == kInf) above.t0 = kInf;
          below_first = !(above.t0 < below.t0);
        }
        const Cell& near = below_first ? below : above;
        const Cell& far = below_first ? above : below;
        const bool near_open = near.t0 <= near.t1;
        if (far.t0 <= far.t1) {
          if (near_open) {
            stack[top++] = far;
          } else {
            cur = far;
            continue;
          }
        }
        if (near_open) {
          cur = near;
          continue;
        }
      } else if (node.item_count() > 0) {
        if (leaf(cur.box(), cur.node, tree.items.subspan(node.first_item(), node.item_count()))) return;
      }
    }
    if (top == 0) return;
    cur = stack[--top];
  }
}

// Each node's box grown as the kd walk grows its cells, the child the
// bound enters first first; a leaf's cell is its box (every item's fuzzy
// box lies inside it).
template <class Limit, class Leaf>
void interval_walk(const BvhView& tree, const IntervalBound& bound, const IntervalBound::Growth& grow,
                   Limit& limit, Leaf&& leaf, std::uint64_t& node_visits) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  struct Pending {
    std::uint32_t node;
    float t;
  };
  std::array<Pending, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  const float t_root = bound.entry(tree.nodes[0].box, grow, limit());
  if (t_root == kInf) return;
  stack[top++] = {0, t_root};
  while (top > 0) {
    const Pending e = stack[--top];
    if (e.t > limit()) continue;
    ++node_visits;
    const BvhNode& node = tree.nodes[e.node];
    if (node.is_leaf()) {
      if (leaf(node.box, e.node, tree.items.subspan(node.first, node.count))) return;
      continue;
    }
    const float t_limit = limit();
    const float ta = bound.entry(tree.nodes[node.first].box, grow, t_limit);
    const float tb = bound.entry(tree.nodes[node.first + 1].box, grow, t_limit);
    const bool a_first = ta <= tb;
    const Pending near{a_first ? node.first : node.first + 1, a_first ? ta : tb};
    const Pending far{a_first ? node.first + 1 : node.first, a_first ? tb : ta};
    if (far.t <= t_limit) stack[top++] = far;
    if (near.t <= t_limit) stack[top++] = near;
  }
}

// Every leaf of `tree` that some ray of `bound` may reach, its cells grown
// by `slack` (IntervalBound::grow_for), until leaf(items) returns false:
// the culls of a whole tile's rays (cull/ray_bound.cpp, cull/static_tiles.cpp).
template <class Leaf>
void for_each_reached_leaf(const KdTreeView& tree, const IntervalBound& bound, float slack, Leaf&& leaf) {
  if (tree.empty()) return;
  const float t_hi = bound.t_hi();
  const auto limit = [t_hi] { return t_hi; };
  std::uint64_t node_visits = 0;
  interval_walk(
      tree, bound, bound.grow_for(tree.bounds, slack), limit,
      [&](const Aabb&, std::uint32_t, std::span<const std::uint32_t> items) { return !leaf(items); }, node_visits);
}

}  // namespace sinew::rt
