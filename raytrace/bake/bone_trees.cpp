// Bone trees (fuzzy bake, bake_steps.h): a tree of the kind the options ask
// for (BVH or kd-tree) per bone over its triangles' fuzzy boxes, built in
// parallel and concatenated in bone order; clusters.cpp builds and appends
// its trees with the same pieces.
#include <algorithm>

#include "raytrace/bake/bake_steps.h"

namespace sinew::rt::bake_detail {

Expected<BuiltTree> build_tree(std::span<const Aabb> boxes, const TreeBuild& build) {
  BuiltTree t;
  if (build.kind == BoneTreeKind::kBvh) {
    SINEW_ASSIGN_OR_RETURN(BoxBvh bvh, build_box_bvh(boxes, build.bvh));
    t.bounds = bvh.view().bounds;
    t.full_leaves = bvh.stats.leaf_count;
    t.item_refs = bvh.stats.item_count;
    t.max_depth = bvh.stats.max_depth;
    t.bvh_nodes = std::move(bvh.nodes);
    t.items = std::move(bvh.items);
    return t;
  }
  SINEW_ASSIGN_OR_RETURN(KdTree kd, build_kd_tree(boxes, build.kd));
  t.bounds = kd.bounds;
  t.full_leaves = kd.stats.leaf_count - kd.stats.empty_leaf_count;
  t.item_refs = kd.stats.item_refs;
  t.max_depth = kd.stats.max_depth;
  t.kd_nodes = std::move(kd.nodes);
  t.items = std::move(kd.items);
  return t;
}

// Appends `tree` (built over `triangles`' boxes, in that order) to the
// character's arrays as the slice `bt`: node indices stay tree-relative,
// item indices become triangle ids.
void append_tree(const BuiltTree& tree, std::span<const std::uint32_t> triangles, FuzzyCharacterData& out,
                 BoneTree& bt) {
  const bool bvh = out.tree_kind == BoneTreeKind::kBvh;
  bt.node_begin = static_cast<std::uint32_t>(bvh ? out.bvh_nodes.size() : out.nodes.size());
  bt.node_count = static_cast<std::uint32_t>(bvh ? tree.bvh_nodes.size() : tree.kd_nodes.size());
  bt.item_begin = static_cast<std::uint32_t>(out.items.size());
  bt.item_count = static_cast<std::uint32_t>(tree.items.size());
  bt.bounds = tree.bounds;
  if (bvh) {
    out.bvh_nodes.insert(out.bvh_nodes.end(), tree.bvh_nodes.begin(), tree.bvh_nodes.end());
  } else {
    out.nodes.insert(out.nodes.end(), tree.kd_nodes.begin(), tree.kd_nodes.end());
  }
  for (std::uint32_t item : tree.items) out.items.push_back(triangles[item]);
}

std::uint32_t tree_node_count(const FuzzyCharacterData& out) {
  return static_cast<std::uint32_t>(out.tree_kind == BoneTreeKind::kBvh ? out.bvh_nodes.size() : out.nodes.size());
}

TreeBuild tree_build_options(const FuzzyBakeOptions& options, std::size_t triangle_count) {
  TreeBuild build{options.bone_trees, options.kd, options.bvh};
  if (options.fine_mesh_cost && triangle_count >= kFineMeshTriangles) {
    build.kd.intersection_cost = kFineMeshIntersectionCost;
  }
  return build;
}

Status build_bone_trees(std::span<const Aabb> triangle_boxes, const FuzzyBakeOptions& options,
                        JobSystem& jobs, FuzzyCharacterData& out) {
  const std::uint32_t bone_count = out.bone_count;
  // Triangles per bone (CSR, ascending triangle ids).
  std::vector<std::uint32_t> begin(bone_count + 1, 0);
  for (std::uint16_t b : out.triangle_bone) ++begin[b + 1u];
  for (std::uint32_t b = 0; b < bone_count; ++b) begin[b + 1] += begin[b];
  std::vector<std::uint32_t> triangles(out.triangle_bone.size());
  {
    std::vector<std::uint32_t> cursor(begin.begin(), begin.end() - 1);
    for (std::size_t t = 0; t < out.triangle_bone.size(); ++t) {
      triangles[cursor[out.triangle_bone[t]]++] = static_cast<std::uint32_t>(t);
    }
  }

  const TreeBuild build = tree_build_options(options, out.triangle_bone.size());
  out.tree_kind = build.kind;
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::optional<BuiltTree>> trees,
                         build_trees(bone_count, build, jobs, [&](std::size_t b, std::vector<Aabb>& boxes) {
                           boxes.reserve(begin[b + 1] - begin[b]);
                           for (std::uint32_t i = begin[b]; i < begin[b + 1]; ++i) {
                             boxes.push_back(triangle_boxes[triangles[i]]);
                           }
                         }));

  // Concatenate in bone order.
  out.bone_trees.assign(bone_count, BoneTree{});
  std::uint64_t full_leaves = 0;
  std::uint64_t item_refs = 0;
  for (std::uint32_t b = 0; b < bone_count; ++b) {
    BoneTree& bt = out.bone_trees[b];
    bt.triangle_count = begin[b + 1] - begin[b];
    bt.node_begin = tree_node_count(out);
    bt.item_begin = static_cast<std::uint32_t>(out.items.size());
    bt.bounds = Aabb::empty();
    if (!trees[b]) continue;
    const BuiltTree& tree = *trees[b];
    append_tree(tree, std::span(triangles).subspan(begin[b], bt.triangle_count), out, bt);
    full_leaves += tree.full_leaves;
    item_refs += tree.item_refs;
    out.stats.max_depth = std::max(out.stats.max_depth, tree.max_depth);
  }
  out.stats.node_count = tree_node_count(out);
  out.stats.mean_items_per_leaf =
      full_leaves ? static_cast<double>(item_refs) / static_cast<double>(full_leaves) : 0.0;
  return {};
}

}  // namespace sinew::rt::bake_detail
