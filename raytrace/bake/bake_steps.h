// The fuzzy bake's steps, private to raytrace/bake: the data they hand on
// and their declarations. bake_fuzzy_character (fuzzy_bake.cpp) runs them
// in this order, one file per step:
//   candidates.cpp     which bones compete for each triangle
//   sweeps.cpp         sample sweeps growing a chunk's vertex boxes, and the
//                      assignment of each triangle to its best bone
//   vertex_checks.cpp  the escape checks of the chosen bones and their boxes
//   clusters.cpp       pose-space clusters: samples, boxes and trees
//   bone_trees.cpp     a tree per bone (and per cluster) over fuzzy boxes
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "raytrace/bake/fuzzy_bake.h"
#include "runtime/jobs/job_system.h"
#include "runtime/math/aabb.h"

namespace sinew::rt::bake_detail {

using Clock = std::chrono::steady_clock;

inline constexpr std::size_t kSamplesPerBatch = 8;  // samples swept per pass over the vertices
inline constexpr std::size_t kVertexGrain = 512;
inline constexpr std::size_t kTriangleGrain = 2048;
// Share of the progress fraction spent before the kd-tree builds start.
inline constexpr double kSweepShare = 0.9;

// Surface area in double: assignment compares areas of boxes that may differ
// only slightly, and the stats sum many of them.
inline double surface_area_d(const Aabb& box) {
  if (box.is_empty()) return 0.0;
  const double dx = static_cast<double>(box.upper.x) - static_cast<double>(box.lower.x);
  const double dy = static_cast<double>(box.upper.y) - static_cast<double>(box.lower.y);
  const double dz = static_cast<double>(box.upper.z) - static_cast<double>(box.lower.z);
  return 2.0 * (dx * dy + dy * dz + dz * dx);
}

inline void pad_box(Aabb& box, float pad) {
  if (box.is_empty()) return;
  box.lower -= Vec3(pad);
  box.upper += Vec3(pad);
}

template <typename T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

// ---------------------------------------------------------------------------
// Progress

// The progress callback's view of the bake: the sample sweeps fill
// [0, kSweepShare), the tree builds the rest, and the fraction never falls.
class Progress {
 public:
  Progress(const FuzzyBakeOptions& options, double sweep_units)
      : callback_(options.progress), sweep_units_(std::max(sweep_units, 1.0)) {}

  // Reports `units` more sample sweeps done.
  Status advance(std::string_view phase, double units) {
    done_units_ += units;
    return report(phase, kSweepShare * std::min(done_units_ / sweep_units_, 1.0));
  }

  Status report(std::string_view phase, double fraction) {
    fraction_ = std::max(fraction_, std::clamp(fraction, 0.0, 1.0));
    if (callback_ && !callback_(phase, fraction_)) {
      return make_error(ErrorCode::kCancelled, "", "progress", std::string(phase),
                        "the progress callback cancelled the bake");
    }
    return {};
  }

 private:
  const std::function<bool(std::string_view, double)>& callback_;
  double sweep_units_;
  double done_units_ = 0.0;
  double fraction_ = 0.0;
};

// ---------------------------------------------------------------------------
// Samples

// The pose samples and their inverses, which every sweep skins the mesh by.
struct Samples {
  const SkinnedMesh& mesh;
  std::span<const Affine3> matrices;  // sample-major, bind pose -> pose
  std::span<const Affine3> inverses;  // pose -> bone frame
  std::uint32_t bone_count;

  std::size_t count() const { return matrices.size() / bone_count; }
  std::span<const Affine3> pose(std::size_t s) const {
    return matrices.subspan(s * bone_count, bone_count);
  }
  const Affine3* bone_from_pose(std::size_t s) const { return inverses.data() + s * bone_count; }
};

// Calls grow(vertices, first_sample, last_sample) over all vertices for
// batches of samples, reporting progress as `phase` between batches
// (sweeps.cpp).
Status sweep_samples(const Samples& samples, JobSystem& jobs, Progress& progress, std::string_view phase,
                     const std::function<void(Range, std::size_t, std::size_t)>& grow);

// ---------------------------------------------------------------------------
// Candidate bones (candidates.cpp)

// Per item (triangle or vertex) a sorted list of bones as CSR, or, when
// `begin` is empty, every bone for every item (CandidateBones::kAll).
struct BoneLists {
  std::vector<std::uint32_t> begin;
  std::vector<std::uint16_t> bones;
  std::vector<std::uint16_t> every_bone;

  std::span<const std::uint16_t> of(std::size_t i) const {
    if (begin.empty()) return every_bone;
    return std::span<const std::uint16_t>(bones).subspan(begin[i], begin[i + 1] - begin[i]);
  }
  std::size_t bytes() const { return bytes_of(begin) + bytes_of(bones) + bytes_of(every_bone); }

  void append(std::vector<std::uint16_t>& list) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    bones.insert(bones.end(), list.begin(), list.end());
    begin.push_back(static_cast<std::uint32_t>(bones.size()));
  }
};

// Which triangles use each vertex (CSR).
struct VertexTriangles {
  std::vector<std::uint32_t> begin;
  std::vector<std::uint32_t> triangles;

  std::span<const std::uint32_t> of(std::size_t v) const {
    return std::span<const std::uint32_t>(triangles).subspan(begin[v], begin[v + 1] - begin[v]);
  }
  std::size_t bytes() const { return bytes_of(begin) + bytes_of(triangles); }
};

// Every bone, each its own representative (merge_rigid_bones off).
std::vector<std::uint16_t> all_bones(std::uint32_t bone_count);
VertexTriangles vertex_triangles(const SkinnedMesh& mesh);
// Per bone its representative: itself, or for a bone that moves rigidly
// with its parent in every sample, the parent's representative.
std::vector<std::uint16_t> moving_representatives(const Samples& samples, std::span<const int> parents);
// The bones standing for themselves (see moving_representatives).
std::vector<std::uint16_t> represented_bones(std::span<const std::uint16_t> rep);
// CandidateBones::kInfluencing: the bones weighting any corner, with their
// parents and children, each replaced by its representative.
BoneLists influencing_candidates(const SkinnedMesh& mesh, std::span<const int> parents,
                                 std::span<const std::uint16_t> rep);
// The bones each vertex needs a box in: the union of its triangles' candidates.
BoneLists vertex_needs(const VertexTriangles& adj, const BoneLists& triangle_candidates,
                       std::size_t vertex_count);

// ---------------------------------------------------------------------------
// Chunk sweeps and assignment (sweeps.cpp)

// A chunk of candidate bones [first, last) with a dense vertex x bone box array.
struct BoxChunk {
  std::uint32_t first = 0;
  std::uint32_t last = 0;
  std::vector<Aabb> boxes;  // boxes[v * width() + (b - first)]

  std::size_t width() const { return last - first; }
  Aabb& at(std::size_t v, std::uint32_t bone) { return boxes[v * width() + (bone - first)]; }
  const Aabb& at(std::size_t v, std::uint32_t bone) const {
    return boxes[v * width() + (bone - first)];
  }
};

// Grows, for the chunk's bones each vertex needs, its boxes over every
// sample, padded by `pad`.
Status grow_chunk_boxes(const Samples& samples, const BoneLists& needs, BoxChunk& chunk, float pad,
                        JobSystem& jobs, Progress& progress);

// Each triangle's best candidate so far, updated chunk by chunk.
struct Assignment {
  std::vector<double> area;          // the best candidate's fuzzy box area so far
  std::vector<std::uint16_t> bone;   // the best candidate so far
  std::size_t bytes() const { return bytes_of(area) + bytes_of(bone); }
};

// Updates each triangle's best bone with the chunk's candidates.
void assign_chunk(const SkinnedMesh& mesh, const BoneLists& candidates, const BoxChunk& chunk,
                  Assignment& best, JobSystem& jobs);

// ---------------------------------------------------------------------------
// Escape checks (vertex_checks.cpp)

// One check per distinct bone among each vertex's triangles, sorted by bone.
void make_vertex_checks(const VertexTriangles& adj, std::span<const std::uint16_t> triangle_bone,
                        std::size_t vertex_count, FuzzyCharacterData& out);
// Grows each check's box over every sample, padded by `pad`.
Status grow_check_boxes(const Samples& samples, float pad, JobSystem& jobs, Progress& progress,
                        FuzzyCharacterData& out);
// Each triangle corner's check in the triangle's bone.
void link_triangle_checks(const SkinnedMesh& mesh, FuzzyCharacterData& out);
// Each triangle's fuzzy box: the union of its corners' check boxes.
std::vector<Aabb> triangle_fuzzy_boxes(const FuzzyCharacterData& out);

// ---------------------------------------------------------------------------
// Bone trees (bone_trees.cpp)

// The trees of a bake, of the kind FuzzyBakeOptions::bone_trees asks for.
struct TreeBuild {
  BoneTreeKind kind = BoneTreeKind::kKdTree;
  KdBuildOptions kd;
  BvhBuildOptions bvh;
};

// One bone's (or cluster's) tree before concatenation: items index the
// boxes it was built over.
struct BuiltTree {
  std::vector<KdNode> kd_nodes;
  std::vector<BvhNode> bvh_nodes;
  std::vector<std::uint32_t> items;
  Aabb bounds;
  std::uint64_t full_leaves = 0;
  std::uint64_t item_refs = 0;
  int max_depth = 0;
};

// One tree of build.kind over `boxes`; its items index `boxes`.
Expected<BuiltTree> build_tree(std::span<const Aabb> boxes, const TreeBuild& build);

// `count` trees in parallel, tree i over the boxes fill(i, boxes) puts in
// `boxes` (none when it puts none); the first error, if any.
template <class Fill>
Expected<std::vector<std::optional<BuiltTree>>> build_trees(std::size_t count, const TreeBuild& build,
                                                            JobSystem& jobs, Fill&& fill) {
  std::vector<std::optional<BuiltTree>> trees(count);
  std::vector<Status> errors(count);
  jobs.parallel_for(0, count, 1, [&](Range r) {
    for (std::size_t i = r.begin; i < r.end; ++i) {
      std::vector<Aabb> boxes;
      fill(i, boxes);
      if (boxes.empty()) continue;
      Expected<BuiltTree> tree = build_tree(boxes, build);
      if (tree.ok()) {
        trees[i] = std::move(tree).value();
      } else {
        errors[i] = std::move(tree).status();
      }
    }
  });
  for (const Status& error : errors) SINEW_RETURN_IF_ERROR(error);
  return trees;
}

// Appends `tree` (built over `triangles`' boxes, in that order) to the
// character's arrays as the slice `bt`.
void append_tree(const BuiltTree& tree, std::span<const std::uint32_t> triangles, FuzzyCharacterData& out,
                 BoneTree& bt);
// The nodes so far in the character's array of its tree kind.
std::uint32_t tree_node_count(const FuzzyCharacterData& out);
// The build options, with kFineMeshIntersectionCost on fine meshes.
TreeBuild tree_build_options(const FuzzyBakeOptions& options, std::size_t triangle_count);
// A tree per bone over its triangles' fuzzy boxes, concatenated in bone order.
Status build_bone_trees(std::span<const Aabb> triangle_boxes, const FuzzyBakeOptions& options,
                        JobSystem& jobs, FuzzyCharacterData& out);

// ---------------------------------------------------------------------------
// Pose-space clusters (clusters.cpp)

// Per bone, each sample's cluster (empty for a bone without clusters).
using ClusterMembers = std::vector<std::vector<std::uint32_t>>;

// Clusters each bone's samples and lays out the clusters, their centres
// and the check ranks.
ClusterMembers plan_clusters(const Samples& samples, std::uint32_t clusters_per_bone, float translation_scale,
                             JobSystem& jobs, FuzzyCharacterData& out);
// Each cluster's boxes of its bone's checks, over the cluster's samples.
Status grow_cluster_boxes(const Samples& samples, const ClusterMembers& members, float pad, JobSystem& jobs,
                          Progress& progress, FuzzyCharacterData& out);
// A tree per cluster, appended after the bone trees; the clusters' stats.
Status build_cluster_trees(const SkinnedMesh& mesh, const TreeBuild& build, JobSystem& jobs,
                           FuzzyCharacterData& out);

}  // namespace sinew::rt::bake_detail
