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

#include "raytrace/kdtree/kd_tree.h"
#include "runtime/core/status.h"
#include "runtime/math/aabb.h"

namespace sinew {
struct SkinnedMesh;
}

namespace sinew::rt {

// One bone's fuzzy kd-tree: a slice of the character's node and item arrays.
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

struct FuzzyCharacterView {
  std::uint32_t bone_count = 0;
  std::span<const std::uint16_t> triangle_bone;             // per triangle: its bone
  std::span<const BoneTree> bone_trees;                     // per bone
  std::span<const KdNode> nodes;                            // all bones' nodes
  std::span<const std::uint32_t> items;                     // all bones' leaf items
  std::span<const std::uint32_t> vertex_check_begin;        // per vertex + 1: CSR into vertex_checks
  std::span<const VertexCheck> vertex_checks;
  std::span<const std::array<std::uint32_t, 3>> triangle_checks;  // per triangle corner: index into vertex_checks

  KdTreeView bone_tree(std::uint32_t bone) const {
    const BoneTree& b = bone_trees[bone];
    return {nodes.subspan(b.node_begin, b.node_count), items.subspan(b.item_begin, b.item_count), b.bounds};
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
};

struct FuzzyCharacterData {
  std::uint32_t bone_count = 0;
  std::vector<std::uint16_t> triangle_bone;
  std::vector<BoneTree> bone_trees;
  std::vector<KdNode> nodes;
  std::vector<std::uint32_t> items;
  std::vector<std::uint32_t> vertex_check_begin;
  std::vector<VertexCheck> vertex_checks;
  std::vector<std::array<std::uint32_t, 3>> triangle_checks;
  FuzzyBakeStats stats;

  FuzzyCharacterView view() const {
    return {bone_count, triangle_bone, bone_trees, nodes, items, vertex_check_begin, vertex_checks,
            triangle_checks};
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
