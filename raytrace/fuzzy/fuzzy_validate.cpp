#include "raytrace/fuzzy/fuzzy_character.h"

#include <cmath>
#include <string>
#include <vector>

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

}  // namespace

Status validate_fuzzy_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  const std::size_t vertices = mesh.vertex_count();
  const std::size_t triangles = mesh.triangle_count();
  if (fuzzy.bone_count == 0 || fuzzy.bone_trees.size() != fuzzy.bone_count) {
    return bad_character("bone_trees", std::to_string(fuzzy.bone_trees.size()),
                         "expected one tree per bone (" + std::to_string(fuzzy.bone_count) + ")");
  }
  if (fuzzy.triangle_bone.size() != triangles || fuzzy.triangle_checks.size() != triangles) {
    return bad_character("triangle_bone", std::to_string(fuzzy.triangle_bone.size()),
                         "expected one entry per triangle (" + std::to_string(triangles) + ")");
  }
  if (fuzzy.vertex_check_begin.size() != vertices + 1 || fuzzy.vertex_check_begin.front() != 0 ||
      fuzzy.vertex_check_begin.back() != fuzzy.vertex_checks.size()) {
    return bad_character("vertex_check_begin", std::to_string(fuzzy.vertex_check_begin.size()),
                         "expected vertex_count + 1 offsets covering the checks");
  }
  if (mesh.joints.size() != vertices || mesh.weights.size() != vertices ||
      (!mesh.normals.empty() && mesh.normals.size() != vertices)) {
    return bad_character("mesh", std::to_string(vertices), "per-vertex arrays differ in length");
  }
  for (std::size_t v = 0; v < vertices; ++v) {
    if (fuzzy.vertex_check_begin[v] > fuzzy.vertex_check_begin[v + 1]) {
      return bad_character("vertex_check_begin[" + std::to_string(v) + "]",
                           std::to_string(fuzzy.vertex_check_begin[v]), "offsets decrease");
    }
    for (const std::uint16_t j : mesh.joints[v]) {
      if (j >= fuzzy.bone_count) {
        return bad_character("joints[" + std::to_string(v) + "]", std::to_string(j), "no such bone");
      }
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
      if (v >= vertices) {
        return bad_character("triangles[" + std::to_string(t) + "]", std::to_string(v), "no such vertex");
      }
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
  return {};
}

}  // namespace sinew::rt
