// The fuzzy bake (paper section 3): from sampled poses to per-bone trees
// over fuzzy boxes (BVHs by default, the paper's kd-trees on request).
//
// For each pose sample, every vertex is skinned and transformed into every
// candidate bone's frame; a vertex's fuzzy box in bone b is the AABB of those
// positions. A triangle's fuzzy box in b is the union of its vertices' boxes;
// it is assigned to the candidate bone with the smallest box surface area
// (ties: the lowest bone index). Each bone then gets an SAH tree over its
// triangles' boxes (FuzzyBakeOptions::bone_trees).
//
// Memory stays bounded for large meshes: boxes are grown for a chunk of
// candidate bones at a time (as many as fit in `memory_budget_bytes`),
// re-skinning the samples per chunk, so a 300k-triangle x 60-bone bake needs
// neither V x B boxes nor samples x V positions at once.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string_view>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew {
class JobSystem;
}

namespace sinew::rt {

struct FuzzyBakeInput {
  const SkinnedMesh* mesh = nullptr;
  std::uint32_t bone_count = 0;
  // Per bone its parent (-1 for a root); used by CandidateBones::kInfluencing.
  std::span<const int> bone_parents;
  // sample_count x bone_count skinning matrices (bind pose -> pose), sample-major.
  std::span<const Affine3> samples;
};

// A fine mesh's trees are built with a lower intersection cost (deeper
// trees, fewer triangles per leaf): faster on fine meshes, slower on coarse
// ones (docs/BENCHMARKS.md).
inline constexpr std::size_t kFineMeshTriangles = 25'000;
inline constexpr float kFineMeshIntersectionCost = 0.05f;

// FuzzyBakeOptions::pose_clusters at most: each cluster is another tree and
// another box per check of its bone.
inline constexpr std::uint32_t kMaxPoseClusters = 64;
// The clusters a fine mesh gets by default (FuzzyBakeOptions::fine_mesh_clusters).
// Each cluster tightens its bone's boxes for the poses near it; on fine
// meshes 16 pay for their bake and memory, and more gain nothing
// (docs/RAYTRACE.md, "Pose-space clusters"; docs/BENCHMARKS.md).
inline constexpr std::uint32_t kFineMeshPoseClusters = 16;

struct FuzzyBakeOptions {
  CandidateBones candidates = CandidateBones::kAll;
  // A bone that moves rigidly with its parent in every sample gives its
  // triangles up to the nearest ancestor that moves: no tighter boxes are
  // lost (the triangles are as rigid in that frame), and the bone's tree,
  // top-level object and per-frame ray transform go (Cally: 17 of 37 bones,
  // its fingers, ponytail, neck and toes). Off: every bone competes.
  bool merge_rigid_bones = true;
  // Every vertex box grows by this fraction of the bind-pose bounding box's
  // diagonal on each side: slack for poses between the samples.
  float padding = 0.0f;
  // The bone trees' build. The renderer's default kernel walks a cell once
  // for a whole packet and lets each leaf triangle pick the groups whose
  // frustum it reaches, so a triangle costs a packet far less, against a
  // cell visit, than it costs a single ray: at the kd builder's single-ray
  // ratio (1.5) the trees split about ten times as often as pays. 0.15
  // suits the 256-ray packets the renderer traces by default, most of all on
  // finely subdivided meshes; single rays would prefer the deeper trees of
  // the single-ray ratio (docs/RAYTRACE.md, "Bone tree build").
  KdBuildOptions kd{.traversal_cost = 1.0f, .intersection_cost = 0.15f, .empty_bonus = 0.2f, .max_leaf_items = 1,
                    .max_depth = 0};
  // The bone trees' structure (docs/RAYTRACE.md, "Bone trees: kd-tree or
  // BVH"): BVHs over the fuzzy boxes (built by `bvh`), each triangle listed
  // once, or the paper's kd-trees (built by `kd`). Measured on every model
  // in shared/content: the BVHs trace at
  // least as fast as the kd-trees, faster on fine meshes, with smaller
  // packs and the same images.
  BoneTreeKind bone_trees = BoneTreeKind::kBvh;
  BvhBuildOptions bvh;
  // When set, a mesh of kFineMeshTriangles or more builds with
  // kFineMeshIntersectionCost instead of kd.intersection_cost: where the
  // triangles are about a pixel, a packet meets a leaf's triangles a few at
  // a time and larger leaves pay (docs/RAYTRACE.md, "Bone tree build").
  // Clear it to build with kd.intersection_cost at every size.
  bool fine_mesh_cost = true;
  // Pose-space clusters per bone (raytrace/fuzzy/pose_clusters.h,
  // docs/RAYTRACE.md "Pose-space clusters"): at most this many, each with a
  // tree and escape boxes over its samples alone, besides the full tree.
  // 0: none (the paper's structure), unless fine_mesh_clusters. At most
  // kMaxPoseClusters.
  std::uint32_t pose_clusters = 0;
  // When set and pose_clusters is 0, a mesh of kFineMeshTriangles or more
  // gets kFineMeshPoseClusters: where the triangles are about a pixel the
  // residual motion near the joints dominates their fuzzy boxes, and the
  // clusters cut it (at 3.6 times the baked data at 855,552 triangles).
  // Clear it for none at every size.
  bool fine_mesh_clusters = true;
  std::size_t memory_budget_bytes = std::size_t{256} << 20;
  // Called from the calling thread with a phase name and the fraction of
  // the whole bake done, in [0, 1], never falling. The phases come in this
  // order, each once: "sampling" (every candidate bone's boxes, and the
  // choice of each triangle's bone), "checks" (the chosen bones' boxes, the
  // escape checks), "clusters" (only when clustering), "build" (the trees).
  // Returning false cancels the bake (kCancelled).
  std::function<bool(std::string_view phase, double fraction)> progress;
};

// Errors: kInvalidArgument (no mesh, no samples, samples not a multiple of
// bone_count, bone_parents of the wrong size, bad padding, pose_clusters
// above kMaxPoseClusters); kInvalidData
// naming the first non-finite sample matrix ("samples[s].bone[b]") or a vertex
// whose joint index is out of range ("joints[v][k]"); kCancelled.
Expected<FuzzyCharacterData> bake_fuzzy_character(const FuzzyBakeInput& input,
                                                  const FuzzyBakeOptions& options, JobSystem& jobs);

}  // namespace sinew::rt
