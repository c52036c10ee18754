#include "raytrace/fuzzy/fuzzy_character.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "runtime/mesh/mesh_checks.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::rt {
namespace {

// Empty boxes hold infinities (lower +inf, upper -inf); only NaN is corrupt.
bool has_nan(const Aabb& b) {
  for (int a = 0; a < 3; ++a) {
    if (std::isnan(b.lower[a]) || std::isnan(b.upper[a])) return true;
  }
  return false;
}

Status bad_character(std::string_view field, std::string value, std::string_view detail) {
  return make_error(ErrorCode::kInvalidData, "character", field, value, detail);
}

// Checks what traversal relies on so that a corrupt pack or a mismatched
// bake cannot make it read out of bounds: node links, leaf item ranges and
// depth within each bone's slice, item values within the triangle count.
Status validate_tree(const KdTreeView& tree, std::uint32_t item_limit, std::uint32_t bone) {
  const std::string where = "bone_trees[" + std::to_string(bone) + "]";
  struct Pending {
    std::uint32_t node;
    int depth;
  };
  std::vector<Pending> stack;
  if (!tree.nodes.empty()) stack.push_back({0, 0});
  std::size_t visited = 0;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    if (++visited > tree.nodes.size()) return bad_character(where, "", "kd-tree nodes form a cycle");
    if (p.depth > kMaxTraversalDepth) {
      return bad_character(where, std::to_string(p.depth), "kd-tree deeper than the traversal supports");
    }
    const KdNode& node = tree.nodes[p.node];
    if (node.is_leaf()) {
      if (std::size_t{node.first_item()} + node.item_count() > tree.items.size()) {
        return bad_character(where + ".nodes[" + std::to_string(p.node) + "]",
                             std::to_string(node.first_item()), "leaf items outside the item array");
      }
      continue;
    }
    if (p.node + 1 >= tree.nodes.size() || node.above_child() >= tree.nodes.size() ||
        node.above_child() <= p.node) {
      return bad_character(where + ".nodes[" + std::to_string(p.node) + "]",
                           std::to_string(node.above_child()), "child index outside the tree");
    }
    if (!std::isfinite(node.split())) {
      return bad_character(where + ".nodes[" + std::to_string(p.node) + "]", "", "split is not finite");
    }
    stack.push_back({p.node + 1, p.depth + 1});
    stack.push_back({node.above_child(), p.depth + 1});
  }
  for (std::size_t i = 0; i < tree.items.size(); ++i) {
    if (tree.items[i] >= item_limit) {
      return bad_character(where + ".items[" + std::to_string(i) + "]", std::to_string(tree.items[i]),
                           "not a triangle of the mesh");
    }
  }
  return {};
}

// Whether a kd-tree walk reaching the cells that `box` overlaps finds
// `item` in every leaf it must. As the builder (kdtree/kd_builder.cpp) does,
// the box is clipped to each child's side of a split, and goes below a
// split when it starts below it, above when it ends above it (a box flat on
// the split goes to one side). Leaf items are sorted (checked before).
// Recursion depth is the tree's, already bounded.
bool listed_where_needed(const KdTreeView& tree, std::uint32_t node_index, std::uint32_t item, const Aabb& box) {
  const KdNode& node = tree.nodes[node_index];
  if (node.is_leaf()) {
    const auto first = tree.items.begin() + node.first_item();
    const auto last = first + node.item_count();
    return std::binary_search(first, last, item);
  }
  const int a = node.axis();
  const float split = node.split();
  const bool below = box.lower[a] < split, above = box.upper[a] > split;
  Aabb below_box = box, above_box = box;
  below_box.upper[a] = std::min(box.upper[a], split);
  above_box.lower[a] = std::max(box.lower[a], split);
  if (!below && !above) {
    return listed_where_needed(tree, node_index + 1, item, box) ||
           listed_where_needed(tree, node.above_child(), item, box);
  }
  return (!below || listed_where_needed(tree, node_index + 1, item, below_box)) &&
         (!above || listed_where_needed(tree, node.above_child(), item, above_box));
}

// The trees against the mesh: the bone slices tile the node and item arrays
// in bone order; leaf items are increasing triangles of the tree's own bone;
// and every triangle is inside its bone's root box and listed in every leaf
// its fuzzy box (the union of its corners' check boxes) overlaps. Together
// with the escape check this is what makes a ray find every triangle.
Status validate_tree_contents(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  std::size_t node_at = 0, item_at = 0;
  std::vector<std::uint32_t> per_bone(fuzzy.bone_count, 0);
  for (const std::uint16_t b : fuzzy.triangle_bone) ++per_bone[b];
  for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
    const BoneTree& bt = fuzzy.bone_trees[b];
    const std::string where = "bone_trees[" + std::to_string(b) + "]";
    if (bt.node_begin != node_at || bt.item_begin != item_at) {
      return bad_character(where + ".node_begin", std::to_string(bt.node_begin),
                           "the bones' slices must follow each other in bone order without gaps or overlap "
                           "(expected nodes from " + std::to_string(node_at) + ", items from " +
                               std::to_string(item_at) + ")");
    }
    node_at += bt.node_count;
    item_at += bt.item_count;
    if (bt.triangle_count != per_bone[b]) {
      return bad_character(where + ".triangle_count", std::to_string(bt.triangle_count),
                           std::to_string(per_bone[b]) + " triangles are assigned to the bone");
    }
    if ((bt.node_count == 0) != (per_bone[b] == 0)) {
      return bad_character(where + ".node_count", std::to_string(bt.node_count),
                           "a bone has a tree exactly when triangles are assigned to it");
    }
    const KdTreeView tree = fuzzy.bone_tree(b);
    for (std::size_t n = 0; n < tree.nodes.size(); ++n) {
      const KdNode& node = tree.nodes[n];
      if (!node.is_leaf()) continue;
      if (std::size_t{node.first_item()} + node.item_count() > tree.items.size()) {
        return bad_character(where + ".nodes[" + std::to_string(n) + "]", std::to_string(node.first_item()),
                             "leaf items outside the item array");
      }
      for (std::uint32_t i = 0; i < node.item_count(); ++i) {
        const std::uint32_t t = tree.items[node.first_item() + i];
        if (fuzzy.triangle_bone[t] != b) {
          return bad_character(where + ".items[" + std::to_string(node.first_item() + i) + "]", std::to_string(t),
                               "a triangle of bone " + std::to_string(fuzzy.triangle_bone[t]));
        }
        if (i > 0 && !(tree.items[node.first_item() + i - 1] < t)) {
          return bad_character(where + ".nodes[" + std::to_string(n) + "]", std::to_string(t),
                               "leaf items must increase");
        }
      }
    }
  }
  if (node_at != fuzzy.nodes.size() || item_at != fuzzy.items.size()) {
    return bad_character("bone_trees", std::to_string(node_at) + " nodes, " + std::to_string(item_at) + " items",
                         "the slices must cover the " + std::to_string(fuzzy.nodes.size()) + " nodes and " +
                             std::to_string(fuzzy.items.size()) + " items");
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t b = fuzzy.triangle_bone[t];
    Aabb box;
    for (const std::uint32_t c : fuzzy.triangle_checks[t]) box.extend(fuzzy.vertex_checks[c].box);
    const KdTreeView tree = fuzzy.bone_tree(b);
    const std::string field = "triangle_bone[" + std::to_string(t) + "]";
    for (int a = 0; a < 3; ++a) {
      if (!(box.lower[a] >= tree.bounds.lower[a] && box.upper[a] <= tree.bounds.upper[a])) {
        return bad_character(field, std::to_string(b), "the triangle's fuzzy box leaves its bone tree's bounds");
      }
    }
    if (!listed_where_needed(tree, 0, static_cast<std::uint32_t>(t), box)) {
      return bad_character(field, std::to_string(b),
                           "the triangle is missing from a leaf of its bone's tree that its fuzzy box overlaps");
    }
  }
  return {};
}

}  // namespace

Status validate_fuzzy_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  const std::size_t vertices = mesh.vertex_count();
  const std::size_t triangles = mesh.triangle_count();
  if (fuzzy.bone_count == 0 || fuzzy.bone_trees.size() != fuzzy.bone_count) {
    return bad_character("bone_trees", std::to_string(fuzzy.bone_trees.size()),
                         "expected one tree per bone (" + std::to_string(fuzzy.bone_count) + ")");
  }
  // The mesh first: everything below indexes through it.
  SINEW_RETURN_IF_ERROR(check_skinned_mesh(MeshOrigin{"character", ""}, mesh, fuzzy.bone_count));
  if (fuzzy.triangle_bone.size() != triangles || fuzzy.triangle_checks.size() != triangles) {
    return bad_character("triangle_bone", std::to_string(fuzzy.triangle_bone.size()),
                         "expected one entry per triangle (" + std::to_string(triangles) + ")");
  }
  if (fuzzy.vertex_check_begin.size() != vertices + 1 || fuzzy.vertex_check_begin.front() != 0 ||
      fuzzy.vertex_check_begin.back() != fuzzy.vertex_checks.size()) {
    return bad_character("vertex_check_begin", std::to_string(fuzzy.vertex_check_begin.size()),
                         "expected vertex_count + 1 offsets covering the checks");
  }
  for (std::size_t v = 0; v < vertices; ++v) {
    if (fuzzy.vertex_check_begin[v] > fuzzy.vertex_check_begin[v + 1]) {
      return bad_character("vertex_check_begin[" + std::to_string(v) + "]",
                           std::to_string(fuzzy.vertex_check_begin[v]), "offsets decrease");
    }
  }
  for (std::size_t c = 0; c < fuzzy.vertex_checks.size(); ++c) {
    if (fuzzy.vertex_checks[c].bone >= fuzzy.bone_count) {
      return bad_character("vertex_checks[" + std::to_string(c) + "].bone",
                           std::to_string(fuzzy.vertex_checks[c].bone), "no such bone");
    }
    if (has_nan(fuzzy.vertex_checks[c].box)) {
      return bad_character("vertex_checks[" + std::to_string(c) + "].box", "NaN", "box is not a number");
    }
  }
  for (std::size_t t = 0; t < triangles; ++t) {
    if (fuzzy.triangle_bone[t] >= fuzzy.bone_count) {
      return bad_character("triangle_bone[" + std::to_string(t) + "]",
                           std::to_string(fuzzy.triangle_bone[t]), "no such bone");
    }
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.triangles[t][static_cast<std::size_t>(i)];
      const std::uint32_t c = fuzzy.triangle_checks[t][static_cast<std::size_t>(i)];
      // Each corner's check must be the vertex's check in the triangle's
      // bone: the fallback and escape logic read it as such.
      if (c < fuzzy.vertex_check_begin[v] || c >= fuzzy.vertex_check_begin[v + 1] ||
          fuzzy.vertex_checks[c].bone != fuzzy.triangle_bone[t]) {
        return bad_character("triangle_checks[" + std::to_string(t) + "]", std::to_string(c),
                             "not the corner vertex's check in the triangle's bone");
      }
    }
  }
  for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
    const BoneTree& tree = fuzzy.bone_trees[b];
    if (has_nan(tree.bounds)) {
      return bad_character("bone_trees[" + std::to_string(b) + "].bounds", "NaN", "box is not a number");
    }
    if (std::size_t{tree.node_begin} + tree.node_count > fuzzy.nodes.size() ||
        std::size_t{tree.item_begin} + tree.item_count > fuzzy.items.size()) {
      return bad_character("bone_trees[" + std::to_string(b) + "]", std::to_string(tree.node_begin),
                           "slice outside the node or item array");
    }
    SINEW_RETURN_IF_ERROR(validate_tree(fuzzy.bone_tree(b), static_cast<std::uint32_t>(triangles), b));
  }
  return validate_tree_contents(mesh, fuzzy);
}

}  // namespace sinew::rt
