// The baked, immutable ray-tracing data of one character (paper section 3),
// shared by all its instances (docs/DESIGN.md section 4, "instances share").
//
// Bone frame. A bone's frame is the frame its skinning matrix S_b maps from
// (bind-pose model space relative to that bone): a point p in world space is
// S_b^-1 p in bone b's frame. At the bind pose every frame coincides with
// model space, so a rigidly attached vertex keeps its rest position in its
// bone's frame in every pose: its fuzzy box is a point.
//
// FuzzyCharacterData owns its arrays (an in-memory bake); FuzzyCharacterView
// is the same data as spans, which is what the renderer reads, so a content
// pack can be used in place.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/accel/box_bvh.h"
#include "raytrace/accel/kd_tree.h"
#include "runtime/core/status.h"
#include "runtime/math/aabb.h"

namespace sinew {
struct SkinnedMesh;
}

namespace sinew::rt {

// The structure over a bone's fuzzy boxes (FuzzyBakeOptions::bone_trees):
// the paper's kd-tree, or a BVH listing each triangle once (accel/box_bvh.h,
// docs/RAYTRACE.md "Bone trees: kd-tree or BVH"). One kind for
// every tree of a character.
enum class BoneTreeKind : std::uint8_t { kKdTree = 0, kBvh = 1 };

// One bone's fuzzy tree: a slice of the character's node array (kd-tree
// nodes, or BVH nodes when the character's trees are BVHs) and item array.
// Items are triangle ids of the mesh. `bounds` is the fuzzy root box (the
// union of the bone's triangles' fuzzy boxes, in the bone's frame).
struct BoneTree {
  std::uint32_t node_begin = 0;
  std::uint32_t node_count = 0;
  std::uint32_t item_begin = 0;
  std::uint32_t item_count = 0;
  std::uint32_t triangle_count = 0;  // triangles assigned to this bone
  std::uint32_t reserved = 0;
  Aabb bounds;
};
static_assert(sizeof(BoneTree) == 48);

// The escape check of one (vertex, bone) pair: the vertex's fuzzy box in the
// bone's frame. A vertex has one check per distinct bone among the bones of
// the triangles using it.
struct VertexCheck {
  std::uint32_t bone = 0;
  Aabb box;
};
static_assert(sizeof(VertexCheck) == 28);

// Pose-space clusters (FuzzyBakeOptions::pose_clusters, docs/RAYTRACE.md
// "Pose-space clusters"): a bone's pose samples split by how the bones that
// move its triangles sit relative to it, and per cluster a tighter tree over
// the same triangles and the boxes of the bone's escape checks over that
// cluster's samples alone. Each frame a bone picks the cluster whose centre
// is nearest its pose; the escape check then proves its vertices inside the
// cluster's boxes, or the bone falls back to its full tree.
struct BoneCluster {
  BoneTree tree;                  // a slice of the character's node and item arrays, the bone's triangles
  std::uint32_t box_begin = 0;    // into cluster_boxes: one box per boxed check of the bone, by check_rank
  std::uint32_t centre_begin = 0; // into cluster_centres: 12 floats per feature bone of the bone
};
static_assert(sizeof(BoneCluster) == 56);

// The feature a bone's clusters are told apart by: for each of its feature
// bones j, the 3x4 matrix S_b^-1 S_j (row-major), its translation column
// divided by `translation_scale` (the bind-pose bounds' diagonal) so that a
// move across the model weighs about as a turn of a radian.
inline constexpr std::size_t kClusterFeatureFloats = 12;

// FuzzyCharacterView::check_rank of a check without boxes of its own per cluster.
inline constexpr std::uint32_t kSharedCheckBox = 0xFFFFFFFFu;

struct FuzzyCharacterView {
  std::uint32_t bone_count = 0;
  std::span<const std::uint16_t> triangle_bone;             // per triangle: its bone
  std::span<const BoneTree> bone_trees;                     // per bone
  BoneTreeKind tree_kind = BoneTreeKind::kKdTree;
  std::span<const KdNode> nodes;                            // all bones' kd-tree nodes (empty with BVHs)
  std::span<const BvhNode> bvh_nodes;                       // all bones' BVH nodes (empty with kd-trees)
  std::span<const std::uint32_t> items;                     // all bones' leaf items
  std::span<const std::uint32_t> vertex_check_begin;        // per vertex + 1: CSR into vertex_checks
  std::span<const VertexCheck> vertex_checks;
  std::span<const std::array<std::uint32_t, 3>> triangle_checks;  // per triangle corner: index into vertex_checks
  // Pose-space clusters; all empty without them.
  std::span<const std::uint32_t> bone_cluster_begin;  // per bone + 1: CSR into clusters
  std::span<const BoneCluster> clusters;
  // Per vertex check: its index among its bone's checks with a box per
  // cluster, or kSharedCheckBox for a check whose vertex only its bone
  // weights (rigid in the bone's frame: one box, the full one, serves
  // every cluster).
  std::span<const std::uint32_t> check_rank;
  std::span<const Aabb> cluster_boxes;
  std::span<const std::uint32_t> feature_bone_begin;  // per bone + 1: CSR into feature_bones
  std::span<const std::uint16_t> feature_bones;
  std::span<const float> cluster_centres;
  float feature_translation_scale = 1.0f;

  bool has_bvhs() const { return tree_kind == BoneTreeKind::kBvh; }
  // Kd-trees only (has_bvhs() false).
  KdTreeView bone_tree(std::uint32_t bone) const { return tree_view(bone_trees[bone]); }
  KdTreeView tree_view(const BoneTree& b) const {
    return {nodes.subspan(b.node_begin, b.node_count), items.subspan(b.item_begin, b.item_count), b.bounds};
  }
  // BVHs only (has_bvhs() true).
  BvhView bvh_view(const BoneTree& b) const {
    return {bvh_nodes.subspan(b.node_begin, b.node_count), items.subspan(b.item_begin, b.item_count), b.bounds};
  }
  bool has_clusters() const { return !clusters.empty(); }
  // The box `cluster` holds vertex check `check` to.
  const Aabb& cluster_check_box(const BoneCluster& cluster, std::uint32_t check) const {
    const std::uint32_t rank = check_rank[check];
    return rank == kSharedCheckBox ? vertex_checks[check].box : cluster_boxes[cluster.box_begin + rank];
  }
  std::span<const BoneCluster> bone_clusters(std::uint32_t bone) const {
    if (bone_cluster_begin.empty()) return {};
    return clusters.subspan(bone_cluster_begin[bone], bone_cluster_begin[bone + 1] - bone_cluster_begin[bone]);
  }
  std::span<const std::uint16_t> bone_feature_bones(std::uint32_t bone) const {
    if (feature_bone_begin.empty()) return {};
    return feature_bones.subspan(feature_bone_begin[bone], feature_bone_begin[bone + 1] - feature_bone_begin[bone]);
  }
};

enum class CandidateBones : std::uint8_t {
  kAll,          // every bone (exhaustive, the paper's choice)
  kInfluencing,  // bones influencing the triangle's vertices, their parents and children
};

struct FuzzyBakeStats {
  std::uint32_t sample_count = 0;
  std::uint32_t vertex_count = 0;
  std::uint32_t triangle_count = 0;
  std::uint32_t bone_count = 0;
  CandidateBones candidates = CandidateBones::kAll;
  bool merge_rigid_bones = false;  // FuzzyBakeOptions::merge_rigid_bones
  std::uint32_t merged_bones = 0;  // bones that moved rigidly with their parent and stood for it
  double fuzzy_area = 0.0;          // sum over triangles of their fuzzy box surface areas
  double rest_area = 0.0;           // the same sum for the bind-pose triangle boxes (a lower bound)
  double mean_items_per_leaf = 0.0; // over all bones' non-empty leaves
  int max_depth = 0;                // deepest bone tree
  std::uint32_t node_count = 0;
  double sampling_ms = 0.0;         // skinning the samples and growing the boxes
  double assignment_ms = 0.0;       // choosing each triangle's bone
  double build_ms = 0.0;            // building the kd-trees
  std::size_t peak_bytes = 0;       // the largest working set the bake allocated at once
  std::uint32_t clusters_per_bone = 0;  // FuzzyBakeOptions::pose_clusters (0: none)
  std::uint32_t cluster_count = 0;      // clusters over all bones (bones whose triangles never move have none)
  // The sum over triangles of their fuzzy box area averaged over their
  // bone's clusters (a bone without clusters counts its full tree's box):
  // beside fuzzy_area, what the clusters tighten.
  double cluster_fuzzy_area = 0.0;
  double clustering_ms = 0.0;           // clustering the samples and growing the cluster boxes
};

struct FuzzyCharacterData {
  std::uint32_t bone_count = 0;
  std::vector<std::uint16_t> triangle_bone;
  std::vector<BoneTree> bone_trees;
  BoneTreeKind tree_kind = BoneTreeKind::kKdTree;
  std::vector<KdNode> nodes;
  std::vector<BvhNode> bvh_nodes;
  std::vector<std::uint32_t> items;
  std::vector<std::uint32_t> vertex_check_begin;
  std::vector<VertexCheck> vertex_checks;
  std::vector<std::array<std::uint32_t, 3>> triangle_checks;
  std::vector<std::uint32_t> bone_cluster_begin;
  std::vector<BoneCluster> clusters;
  std::vector<std::uint32_t> check_rank;
  std::vector<Aabb> cluster_boxes;
  std::vector<std::uint32_t> feature_bone_begin;
  std::vector<std::uint16_t> feature_bones;
  std::vector<float> cluster_centres;
  float feature_translation_scale = 1.0f;
  FuzzyBakeStats stats;

  FuzzyCharacterView view() const {
    return {bone_count,         triangle_bone, bone_trees,         tree_kind,     nodes,         bvh_nodes, items,
            vertex_check_begin, vertex_checks, triangle_checks,    bone_cluster_begin,
            clusters,           check_rank,    cluster_boxes,      feature_bone_begin,
            feature_bones,      cluster_centres, feature_translation_scale};
  }
};

// Checks what traversal, skinning and the escape check rely on, so that a
// corrupt pack or a bake of another mesh cannot make them read out of bounds
// or loop: array sizes against the mesh, bone and vertex indices, each
// triangle corner's check, tree slices, node links (children after their
// parent, no cycles), depth within kMaxTraversalDepth, leaf item ranges,
// finite splits, and no NaN in any box. Errors (kInvalidData) name the
// array and the index.
Status validate_fuzzy_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy);

}  // namespace sinew::rt
