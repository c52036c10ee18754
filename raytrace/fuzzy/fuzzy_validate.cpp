#include "raytrace/fuzzy/fuzzy_character.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
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

// Depth first over a tree's nodes from the root: `visit(node, push)` checks
// one node and push(child) queues each child one level deeper. A node
// reached twice (links that form a cycle) or deeper than the traversal's
// fixed stack holds is refused, naming the tree (`kind`: "kd-tree", "BVH").
template <class Visit>
Status walk_nodes(std::size_t node_count, const std::string& where, std::string_view kind, Visit&& visit) {
  struct Pending {
    std::uint32_t node;
    int depth;
  };
  std::vector<Pending> stack;
  if (node_count != 0) stack.push_back({0, 0});
  std::size_t visited = 0;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    if (++visited > node_count) return bad_character(where, "", std::string(kind) + " nodes form a cycle");
    if (p.depth > kMaxTraversalDepth) {
      return bad_character(where, std::to_string(p.depth), std::string(kind) + " deeper than the traversal supports");
    }
    SINEW_RETURN_IF_ERROR(visit(p.node, [&](std::uint32_t child) { stack.push_back({child, p.depth + 1}); }));
  }
  return {};
}

// Checks what traversal relies on so that a corrupt pack or a mismatched
// bake cannot make it read out of bounds: node links, leaf item ranges and
// depth within each bone's slice, item values within the triangle count.
Status validate_tree(const KdTreeView& tree, std::uint32_t item_limit, const std::string& where) {
  SINEW_RETURN_IF_ERROR(walk_nodes(tree.nodes.size(), where, "kd-tree", [&](std::uint32_t n, auto&& push) -> Status {
    const KdNode& node = tree.nodes[n];
    if (node.is_leaf()) {
      if (std::size_t{node.first_item()} + node.item_count() > tree.items.size()) {
        return bad_character(where + ".nodes[" + std::to_string(n) + "]", std::to_string(node.first_item()),
                             "leaf items outside the item array");
      }
      return {};
    }
    if (n + 1 >= tree.nodes.size() || node.above_child() >= tree.nodes.size() || node.above_child() <= n) {
      return bad_character(where + ".nodes[" + std::to_string(n) + "]", std::to_string(node.above_child()),
                           "child index outside the tree");
    }
    if (!std::isfinite(node.split())) {
      return bad_character(where + ".nodes[" + std::to_string(n) + "]", "", "split is not finite");
    }
    push(n + 1);
    push(node.above_child());
    return {};
  }));
  for (std::size_t i = 0; i < tree.items.size(); ++i) {
    if (tree.items[i] >= item_limit) {
      return bad_character(where + ".items[" + std::to_string(i) + "]", std::to_string(tree.items[i]),
                           "not a triangle of the mesh");
    }
  }
  return {};
}

// Whether a kd-tree walk reaching the cells that `box` overlaps finds
// `item` in every leaf it must. As the builder (accel/kd_builder.cpp) does,
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

// A BVH bone tree against the bone's triangles: node links (children
// adjacent, after their parent, inside the slice), depth, leaf ranges that
// partition the items, each triangle of the bone listed exactly once, and
// boxes that hold what lies below them: each leaf's box its items' fuzzy
// boxes (box_of), each inner node's box its children's. Containment is
// transitive, so a walk that enters every node box a ray passes within its
// slack of reaches every triangle whose fuzzy box the ray passes.
// Which BVH last listed each triangle (BvhSeen::tree per tree walked): a
// triangle stamped by the tree being walked is listed twice there.
struct BvhSeen {
  std::vector<std::uint32_t> stamp;
  std::uint32_t tree = 0;
};

template <class BoxOf>
Status validate_bvh(const FuzzyCharacterView& fuzzy, const BvhView& tree, std::uint32_t b,
                    std::span<const std::uint32_t> bone_triangles, const std::string& where, BvhSeen& seen,
                    BoxOf&& box_of) {
  const auto node_field = [&](std::size_t n) { return where + ".bvh_nodes[" + std::to_string(n) + "]"; };
  for (std::size_t n = 0; n < tree.nodes.size(); ++n) {
    if (has_nan(tree.nodes[n].box)) return bad_character(node_field(n) + ".box", "NaN", "box is not a number");
  }
  if (tree.items.size() != bone_triangles.size()) {
    return bad_character(where + ".item_count", std::to_string(tree.items.size()),
                         "a BVH lists each of the bone's " + std::to_string(bone_triangles.size()) +
                             " triangles once");
  }
  // As many items as the bone has triangles (above), each of bone b and
  // none twice (at the leaves): every triangle of the bone is listed.
  seen.stamp.resize(fuzzy.triangle_bone.size(), 0);
  const std::uint32_t stamp = ++seen.tree;
  std::size_t items_listed = 0;
  std::vector<std::uint8_t> item_listed(tree.items.size(), 0);
  SINEW_RETURN_IF_ERROR(walk_nodes(tree.nodes.size(), where, "BVH", [&](std::uint32_t n, auto&& push) -> Status {
    const BvhNode& node = tree.nodes[n];
    if (node.is_leaf()) {
      if (std::size_t{node.first} + node.count > tree.items.size()) {
        return bad_character(node_field(n), std::to_string(node.first), "leaf items outside the item array");
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        if (item_listed[i]++ != 0) {
          return bad_character(node_field(n), std::to_string(i), "an item listed by two leaves");
        }
        ++items_listed;
        const std::uint32_t t = tree.items[i];
        if (t >= fuzzy.triangle_bone.size()) {
          return bad_character(where + ".items[" + std::to_string(i) + "]", std::to_string(t),
                               "not a triangle of the mesh");
        }
        if (fuzzy.triangle_bone[t] != b) {
          return bad_character(where + ".items[" + std::to_string(i) + "]", std::to_string(t),
                               "a triangle of bone " + std::to_string(fuzzy.triangle_bone[t]));
        }
        if (seen.stamp[t] == stamp) {
          return bad_character(where + " triangle " + std::to_string(t), std::to_string(b),
                               "listed twice in one BVH (and another of the bone's triangles not at all)");
        }
        seen.stamp[t] = stamp;
        if (i > node.first && !(tree.items[i - 1] < t)) {
          return bad_character(node_field(n), std::to_string(t), "leaf items must increase");
        }
        if (!node.box.contains(box_of(t))) {
          return bad_character(where + " triangle " + std::to_string(t), std::to_string(b),
                               "the triangle's fuzzy box leaves its BVH leaf's box");
        }
      }
      return {};
    }
    if (node.first <= n || std::size_t{node.first} + 1 >= tree.nodes.size()) {
      return bad_character(node_field(n), std::to_string(node.first), "child index outside the tree");
    }
    for (std::uint32_t c = node.first; c <= node.first + 1; ++c) {
      if (!node.box.contains(tree.nodes[c].box)) {
        return bad_character(node_field(c), std::to_string(c), "a child's box leaves its parent's");
      }
      push(c);
    }
    return {};
  }));
  if (items_listed != tree.items.size()) {
    return bad_character(where + ".items", std::to_string(items_listed) + " listed",
                         "the leaves must list all " + std::to_string(tree.items.size()) + " items");
  }
  if (!tree.nodes.empty() && !tree.bounds.contains(tree.nodes.front().box)) {
    return bad_character(where + ".bounds", std::to_string(b), "the root's box leaves the tree's bounds");
  }
  return {};
}

// One tree of bone b (its full tree or a cluster's) against the mesh: its
// slice starts where the previous one ended, its leaf items are increasing
// triangles of b, and every triangle of b is inside its root box and listed
// in every leaf its fuzzy box (box_of(t): the union of its corners' boxes
// for this tree) overlaps. Together with the escape check this is what
// makes a ray find every triangle.
template <class BoxOf>
Status validate_tree_slice(const FuzzyCharacterView& fuzzy, const BoneTree& bt, std::uint32_t b,
                           std::span<const std::uint32_t> bone_triangles, const std::string& where,
                           std::size_t& node_at, std::size_t& item_at, BvhSeen& seen, BoxOf&& box_of) {
  if (bt.node_begin != node_at || bt.item_begin != item_at) {
    return bad_character(where + ".node_begin", std::to_string(bt.node_begin),
                         "the trees' slices must follow each other in order (bones, then clusters) without gaps "
                         "or overlap (expected nodes from " + std::to_string(node_at) + ", items from " +
                             std::to_string(item_at) + ")");
  }
  if (has_nan(bt.bounds)) return bad_character(where + ".bounds", "NaN", "box is not a number");
  const std::size_t node_total = fuzzy.has_bvhs() ? fuzzy.bvh_nodes.size() : fuzzy.nodes.size();
  if (std::size_t{bt.node_begin} + bt.node_count > node_total ||
      std::size_t{bt.item_begin} + bt.item_count > fuzzy.items.size()) {
    return bad_character(where, std::to_string(bt.node_begin), "slice outside the node or item array");
  }
  node_at += bt.node_count;
  item_at += bt.item_count;
  if (bt.triangle_count != bone_triangles.size()) {
    return bad_character(where + ".triangle_count", std::to_string(bt.triangle_count),
                         std::to_string(bone_triangles.size()) + " triangles are assigned to the bone");
  }
  if ((bt.node_count == 0) != bone_triangles.empty()) {
    return bad_character(where + ".node_count", std::to_string(bt.node_count),
                         "a bone has a tree exactly when triangles are assigned to it");
  }
  if (fuzzy.has_bvhs()) return validate_bvh(fuzzy, fuzzy.bvh_view(bt), b, bone_triangles, where, seen, box_of);
  const KdTreeView tree = fuzzy.tree_view(bt);
  SINEW_RETURN_IF_ERROR(validate_tree(tree, static_cast<std::uint32_t>(fuzzy.triangle_bone.size()), where));
  for (std::size_t n = 0; n < tree.nodes.size(); ++n) {
    const KdNode& node = tree.nodes[n];
    if (!node.is_leaf()) continue;
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
  for (const std::uint32_t t : bone_triangles) {
    const Aabb box = box_of(t);
    const std::string field = where + " triangle " + std::to_string(t);
    for (int a = 0; a < 3; ++a) {
      if (!(box.lower[a] >= tree.bounds.lower[a] && box.upper[a] <= tree.bounds.upper[a])) {
        return bad_character(field, std::to_string(b), "the triangle's fuzzy box leaves its tree's bounds");
      }
    }
    if (!listed_where_needed(tree, 0, t, box)) {
      return bad_character(field, std::to_string(b),
                           "the triangle is missing from a leaf of its tree that its fuzzy box overlaps");
    }
  }
  return {};
}

// A CSR offset array: `count` + 1 entries from 0, not decreasing, ending at `total`.
Status validate_offsets(std::span<const std::uint32_t> begin, std::size_t count, std::size_t total,
                        const std::string& name) {
  if (begin.size() != count + 1 || begin.front() != 0 || begin.back() != total) {
    return bad_character(name, std::to_string(begin.size()) + " offsets",
                         "expected " + std::to_string(count + 1) + " offsets from 0 to " + std::to_string(total));
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (begin[i] > begin[i + 1]) return bad_character(name + "[" + std::to_string(i) + "]", std::to_string(begin[i]), "offsets decrease");
  }
  return {};
}

// The clusters' own arrays (FuzzyBakeOptions::pose_clusters): offsets,
// feature bones, check ranks, every cluster's box and centre ranges in
// bounds, finite centres, boxes without NaN. Their trees are checked with
// the bones'.
Status validate_cluster_arrays(const FuzzyCharacterView& fuzzy) {
  const std::uint32_t bones = fuzzy.bone_count;
  SINEW_RETURN_IF_ERROR(validate_offsets(fuzzy.bone_cluster_begin, bones, fuzzy.clusters.size(), "bone_cluster_begin"));
  SINEW_RETURN_IF_ERROR(validate_offsets(fuzzy.feature_bone_begin, bones, fuzzy.feature_bones.size(), "feature_bone_begin"));
  for (std::size_t i = 0; i < fuzzy.feature_bones.size(); ++i) {
    if (fuzzy.feature_bones[i] >= bones) {
      return bad_character("feature_bones[" + std::to_string(i) + "]", std::to_string(fuzzy.feature_bones[i]), "no such bone");
    }
  }
  if (!(std::isfinite(fuzzy.feature_translation_scale) && fuzzy.feature_translation_scale > 0.0f)) {
    return bad_character("feature_translation_scale", std::to_string(fuzzy.feature_translation_scale),
                         "must be finite and positive");
  }
  if (fuzzy.check_rank.size() != fuzzy.vertex_checks.size()) {
    return bad_character("check_rank", std::to_string(fuzzy.check_rank.size()),
                         "expected one rank per vertex check (" + std::to_string(fuzzy.vertex_checks.size()) + ")");
  }
  // The checks of each bone with boxes of their own per cluster: what a
  // cluster's box range must hold and every rank must stay below.
  std::vector<std::uint32_t> boxed(bones, 0);
  for (std::size_t c = 0; c < fuzzy.check_rank.size(); ++c) {
    if (fuzzy.check_rank[c] != kSharedCheckBox) ++boxed[fuzzy.vertex_checks[c].bone];
  }
  for (std::size_t c = 0; c < fuzzy.check_rank.size(); ++c) {
    const std::uint32_t b = fuzzy.vertex_checks[c].bone;
    if (fuzzy.check_rank[c] != kSharedCheckBox && fuzzy.check_rank[c] >= boxed[b] &&
        fuzzy.bone_cluster_begin[b] != fuzzy.bone_cluster_begin[b + 1]) {
      return bad_character("check_rank[" + std::to_string(c) + "]", std::to_string(fuzzy.check_rank[c]),
                           "not below the " + std::to_string(boxed[b]) + " checks of bone " + std::to_string(b) +
                               " with boxes per cluster");
    }
  }
  for (std::uint32_t b = 0; b < bones; ++b) {
    const std::size_t dims = std::size_t{fuzzy.feature_bone_begin[b + 1] - fuzzy.feature_bone_begin[b]} * kClusterFeatureFloats;
    for (std::uint32_t q = fuzzy.bone_cluster_begin[b]; q < fuzzy.bone_cluster_begin[b + 1]; ++q) {
      const BoneCluster& cluster = fuzzy.clusters[q];
      const std::string where = "clusters[" + std::to_string(q) + "]";
      if (std::size_t{cluster.box_begin} + boxed[b] > fuzzy.cluster_boxes.size()) {
        return bad_character(where + ".box_begin", std::to_string(cluster.box_begin),
                             "the bone's " + std::to_string(boxed[b]) + " check boxes run past cluster_boxes (" +
                                 std::to_string(fuzzy.cluster_boxes.size()) + ")");
      }
      if (std::size_t{cluster.centre_begin} + dims > fuzzy.cluster_centres.size()) {
        return bad_character(where + ".centre_begin", std::to_string(cluster.centre_begin),
                             "the centre runs past cluster_centres (" + std::to_string(fuzzy.cluster_centres.size()) + ")");
      }
      for (std::size_t i = 0; i < dims; ++i) {
        if (!std::isfinite(fuzzy.cluster_centres[cluster.centre_begin + i])) {
          return bad_character("cluster_centres[" + std::to_string(cluster.centre_begin + i) + "]",
                               std::to_string(fuzzy.cluster_centres[cluster.centre_begin + i]), "not finite");
        }
      }
    }
  }
  for (std::size_t i = 0; i < fuzzy.cluster_boxes.size(); ++i) {
    if (has_nan(fuzzy.cluster_boxes[i])) return bad_character("cluster_boxes[" + std::to_string(i) + "]", "NaN", "box is not a number");
  }
  return {};
}

// Every tree, the bones' and then the clusters', against the mesh; the
// slices together cover the node and item arrays.
Status validate_tree_contents(const FuzzyCharacterView& fuzzy) {
  std::vector<std::vector<std::uint32_t>> bone_triangles(fuzzy.bone_count);
  for (std::size_t t = 0; t < fuzzy.triangle_bone.size(); ++t) {
    bone_triangles[fuzzy.triangle_bone[t]].push_back(static_cast<std::uint32_t>(t));
  }
  std::size_t node_at = 0, item_at = 0;
  BvhSeen seen;
  for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
    SINEW_RETURN_IF_ERROR(validate_tree_slice(fuzzy, fuzzy.bone_trees[b], b, bone_triangles[b],
                                              "bone_trees[" + std::to_string(b) + "]", node_at, item_at, seen,
                                              [&](std::uint32_t t) {
                                                Aabb box;
                                                for (const std::uint32_t c : fuzzy.triangle_checks[t]) box.extend(fuzzy.vertex_checks[c].box);
                                                return box;
                                              }));
  }
  if (fuzzy.has_clusters()) {
    for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
      for (std::uint32_t q = fuzzy.bone_cluster_begin[b]; q < fuzzy.bone_cluster_begin[b + 1]; ++q) {
        const BoneCluster& cluster = fuzzy.clusters[q];
        if (bone_triangles[b].empty()) {
          return bad_character("clusters[" + std::to_string(q) + "]", std::to_string(b), "clusters of a bone without triangles");
        }
        SINEW_RETURN_IF_ERROR(validate_tree_slice(fuzzy, cluster.tree, b, bone_triangles[b],
                                                  "clusters[" + std::to_string(q) + "].tree", node_at, item_at, seen,
                                                  [&](std::uint32_t t) {
                                                    Aabb box;
                                                    for (const std::uint32_t c : fuzzy.triangle_checks[t]) {
                                                      box.extend(fuzzy.cluster_check_box(cluster, c));
                                                    }
                                                    return box;
                                                  }));
      }
    }
  }
  const std::size_t node_total = fuzzy.has_bvhs() ? fuzzy.bvh_nodes.size() : fuzzy.nodes.size();
  if (node_at != node_total || item_at != fuzzy.items.size()) {
    return bad_character("bone_trees", std::to_string(node_at) + " nodes, " + std::to_string(item_at) + " items",
                         "the slices must cover the " + std::to_string(node_total) + " nodes and " +
                             std::to_string(fuzzy.items.size()) + " items");
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
  if (fuzzy.tree_kind != BoneTreeKind::kKdTree && fuzzy.tree_kind != BoneTreeKind::kBvh) {
    return bad_character("tree_kind", std::to_string(static_cast<int>(fuzzy.tree_kind)), "not a kd-tree or a BVH");
  }
  if (fuzzy.has_bvhs() ? !fuzzy.nodes.empty() : !fuzzy.bvh_nodes.empty()) {
    return bad_character(fuzzy.has_bvhs() ? "nodes" : "bvh_nodes",
                         std::to_string(fuzzy.has_bvhs() ? fuzzy.nodes.size() : fuzzy.bvh_nodes.size()),
                         "a character's trees are all kd-trees or all BVHs");
  }
  const bool any_cluster_array = !fuzzy.bone_cluster_begin.empty() || !fuzzy.clusters.empty() ||
                                 !fuzzy.check_rank.empty() || !fuzzy.cluster_boxes.empty() ||
                                 !fuzzy.feature_bone_begin.empty() || !fuzzy.feature_bones.empty() ||
                                 !fuzzy.cluster_centres.empty();
  if (any_cluster_array) SINEW_RETURN_IF_ERROR(validate_cluster_arrays(fuzzy));
  return validate_tree_contents(fuzzy);
}

}  // namespace sinew::rt
