// The fuzzy bake (paper section 3); the contract is in fuzzy_bake.h.
//
// Pipeline:
//   validate -> invert every sample matrix once
//   -> candidate bones per triangle, and the (vertex, bone) pairs they need
//   -> per chunk of bones: sweep the samples growing the chunk's vertex boxes,
//      then update each triangle's best (smallest-area) bone
//   -> one more sweep for the vertex boxes of the chosen bones (the escape
//      checks), whose unions are the triangles' fuzzy boxes
//   -> with pose_clusters: per bone, its samples clustered by its feature
//      (pose_clusters.h) and one more sweep for each cluster's check boxes
//   -> per bone an SAH tree (BVH or kd-tree) over its triangles' fuzzy
//      boxes, then one per cluster over the cluster's boxes.
//
// Every box is a min/max over samples, which is independent of the order the
// samples and vertices are visited in, so the result depends neither on the
// thread count nor on the chunking.
//
// This file validates the input and runs the steps; each step has its file
// (listed in bake_steps.h).
#include "raytrace/bake/fuzzy_bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "raytrace/bake/bake_steps.h"
#include "runtime/core/format_number.h"
#include "runtime/jobs/job_system.h"
#include "runtime/mesh/mesh_checks.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {

using namespace bake_detail;

namespace {

constexpr std::size_t kMaxBones = 65535;     // triangle_bone is uint16

std::string indexed(std::string_view name, std::size_t i) {
  return std::string(name) + "[" + std::to_string(i) + "]";
}

std::string format_matrix(const Affine3& m) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      out += format_number(m(r, c));
      out += c < 3 ? " " : (r < 2 ? "; " : "]");
    }
  }
  return out;
}

// The working set of the bake, as the sum of its large live buffers.
class MemoryLedger {
 public:
  void hold(std::size_t bytes) {
    current_ += bytes;
    peak_ = std::max(peak_, current_);
  }
  void release(std::size_t bytes) { current_ -= std::min(bytes, current_); }
  std::size_t peak() const { return peak_; }

 private:
  std::size_t current_ = 0;
  std::size_t peak_ = 0;
};

// ---------------------------------------------------------------------------
// Validation

Status validate_input(const FuzzyBakeInput& input, const FuzzyBakeOptions& options) {
  if (input.mesh == nullptr) return invalid_argument("mesh", "null", "there is no mesh to bake");
  const std::uint32_t bones = input.bone_count;
  if (bones == 0) return invalid_argument("bone_count", "0", "a character needs at least one bone");
  if (bones > kMaxBones) {
    return make_error(ErrorCode::kLimitExceeded, "", "bone_count", std::to_string(bones),
                      "more bones than triangle_bone (uint16) can name (65535)");
  }
  // Vertex and triangle ids are 32-bit everywhere past this point.
  constexpr std::size_t kMaxIds = std::numeric_limits<std::uint32_t>::max();
  if (input.mesh->vertex_count() > kMaxIds) {
    return make_error(ErrorCode::kLimitExceeded, "", "vertex_count", std::to_string(input.mesh->vertex_count()),
                      "more vertices than 32-bit ids can name");
  }
  if (input.mesh->triangle_count() > kMaxIds) {
    return make_error(ErrorCode::kLimitExceeded, "", "triangle_count", std::to_string(input.mesh->triangle_count()),
                      "more triangles than 32-bit ids can name");
  }
  if (input.bone_parents.size() != bones) {
    return invalid_argument("bone_parents", std::to_string(input.bone_parents.size()) + " entries",
                            "expected one parent per bone (" + std::to_string(bones) + ")");
  }
  for (std::size_t b = 0; b < bones; ++b) {
    const int parent = input.bone_parents[b];
    if (parent < -1 || parent >= static_cast<int>(bones)) {
      return invalid_argument(indexed("bone_parents", b), std::to_string(parent),
                              "not -1 (a root) or a bone index below " + std::to_string(bones));
    }
  }
  if (input.samples.empty()) {
    return invalid_argument("samples", "0 matrices", "at least one pose sample is needed");
  }
  if (input.samples.size() % bones != 0) {
    return invalid_argument("samples", std::to_string(input.samples.size()) + " matrices",
                            "not a multiple of bone_count (" + std::to_string(bones) + ")");
  }
  if (!std::isfinite(options.padding) || options.padding < 0.0f) {
    return invalid_argument("padding", format_number(options.padding),
                            "must be finite and not negative");
  }
  if (options.pose_clusters > kMaxPoseClusters) {
    return invalid_argument("pose_clusters", std::to_string(options.pose_clusters),
                            "at most " + std::to_string(kMaxPoseClusters));
  }
  if (options.bone_trees != BoneTreeKind::kKdTree && options.bone_trees != BoneTreeKind::kBvh) {
    return invalid_argument("bone_trees", std::to_string(static_cast<int>(options.bone_trees)), "not kd or bvh");
  }
  if (options.bone_trees == BoneTreeKind::kBvh) {
    if (Status s = check_bvh_options(options.bvh); !s.ok()) {
      return invalid_argument("bvh." + std::string(s.field()), s.value(), s.detail());
    }
  }
  return check_skinned_mesh(MeshOrigin{}, *input.mesh, bones);
}

// Inverts every sample matrix once (sample-major, like the input), rejecting
// the first that is not finite or has no finite inverse.
Expected<std::vector<Affine3>> invert_samples(std::span<const Affine3> samples,
                                              std::uint32_t bone_count) {
  std::vector<Affine3> inverses(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::string field = indexed("samples", i / bone_count) + ".bone" + "[" +
                              std::to_string(i % bone_count) + "]";
    if (!is_finite(samples[i])) {
      return make_error(ErrorCode::kInvalidData, "", field, format_matrix(samples[i]),
                        "not finite");
    }
    inverses[i] = inverse(samples[i]);
    if (!is_finite(inverses[i])) {
      return make_error(ErrorCode::kInvalidData, "", field, format_matrix(samples[i]),
                        "singular (a zero-scale bone has no frame to bound vertices in)");
    }
  }
  return inverses;
}

// The triangles' bind-pose box areas: the stats' baseline for fuzzy_area.
double rest_area(const SkinnedMesh& mesh) {
  double sum = 0.0;
  for (const auto& tri : mesh.triangles) {
    Aabb box;
    for (std::uint32_t v : tri) box.extend(mesh.positions[v]);
    sum += surface_area_d(box);
  }
  return sum;
}

// FuzzyBakeOptions::padding as a distance: that fraction of the bind-pose
// bounding box's diagonal.
float padding_distance(const SkinnedMesh& mesh, float padding) {
  Aabb bind;
  for (const Vec3& p : mesh.positions) bind.extend(p);
  if (bind.is_empty()) return 0.0f;
  const Vec3 e = bind.extent();
  const double x = static_cast<double>(e.x);
  const double y = static_cast<double>(e.y);
  const double z = static_cast<double>(e.z);
  const double diagonal = std::sqrt(x * x + y * y + z * z);
  return static_cast<float>(static_cast<double>(padding) * diagonal);
}

// Grows the boxes of `chunk_bones` candidate bones at a time (as many as the
// memory budget holds) and after each chunk keeps each triangle's best bone
// in `best`: the bake's first sweeps, whose times add to `stats`.
Status assign_in_chunks(const Samples& samples, const BoneLists& candidates, const BoneLists& needs,
                        std::uint32_t chunk_bones, float pad, JobSystem& jobs, Progress& progress,
                        MemoryLedger& memory, Assignment& best, FuzzyBakeStats& stats) {
  const std::uint32_t bone_count = samples.bone_count;
  BoxChunk chunk;
  chunk.boxes.resize(samples.mesh.vertex_count() * chunk_bones);
  memory.hold(bytes_of(chunk.boxes));
  for (std::uint32_t first = 0; first < bone_count; first += chunk_bones) {
    chunk.first = first;
    chunk.last = std::min(bone_count, first + chunk_bones);
    const auto sampling_start = Clock::now();
    SINEW_RETURN_IF_ERROR(grow_chunk_boxes(samples, needs, chunk, pad, jobs, progress));
    stats.sampling_ms += ms_since(sampling_start);
    const auto assignment_start = Clock::now();
    assign_chunk(samples.mesh, candidates, chunk, best, jobs);
    stats.assignment_ms += ms_since(assignment_start);
    // The assignment is part of the sampling phase: with bones in several
    // chunks the two alternate, and the phases a user sees never go back.
    SINEW_RETURN_IF_ERROR(progress.advance("sampling", 0.0));
  }
  memory.release(bytes_of(chunk.boxes));
  return {};
}

}  // namespace

Expected<FuzzyCharacterData> bake_fuzzy_character(const FuzzyBakeInput& input,
                                                  const FuzzyBakeOptions& options, JobSystem& jobs) {
  SINEW_RETURN_IF_ERROR(validate_input(input, options));
  const SkinnedMesh& mesh = *input.mesh;
  const std::uint32_t bone_count = input.bone_count;
  const std::size_t vertex_count = mesh.vertex_count();
  const std::size_t triangle_count = mesh.triangle_count();
  MemoryLedger memory;

  auto sampling_start = Clock::now();
  SINEW_ASSIGN_OR_RETURN(std::vector<Affine3> inverses, invert_samples(input.samples, bone_count));
  memory.hold(bytes_of(inverses));
  const Samples samples{mesh, input.samples, inverses, bone_count};
  const float pad = padding_distance(mesh, options.padding);

  FuzzyCharacterData out;
  out.bone_count = bone_count;
  FuzzyBakeStats& stats = out.stats;
  stats.sample_count = static_cast<std::uint32_t>(samples.count());
  stats.vertex_count = static_cast<std::uint32_t>(vertex_count);
  stats.triangle_count = static_cast<std::uint32_t>(triangle_count);
  stats.bone_count = bone_count;
  stats.candidates = options.candidates;
  stats.sampling_ms = ms_since(sampling_start);

  // Candidates per triangle and the (vertex, bone) pairs they need.
  auto assignment_start = Clock::now();
  VertexTriangles adj = vertex_triangles(mesh);
  memory.hold(adj.bytes());
  BoneLists candidates;
  BoneLists needs;
  std::vector<std::uint16_t> rep = all_bones(bone_count);
  if (options.merge_rigid_bones) rep = moving_representatives(samples, input.bone_parents);
  const std::vector<std::uint16_t> represented = represented_bones(rep);
  if (options.candidates == CandidateBones::kInfluencing) {
    candidates = influencing_candidates(mesh, input.bone_parents, rep);
    needs = vertex_needs(adj, candidates, vertex_count);
  } else {
    candidates.every_bone = represented;
    needs.every_bone = candidates.every_bone;
  }
  stats.merge_rigid_bones = options.merge_rigid_bones;
  stats.merged_bones = bone_count - static_cast<std::uint32_t>(represented.size());
  memory.hold(candidates.bytes() + needs.bytes());
  Assignment best;
  best.area.assign(triangle_count, std::numeric_limits<double>::infinity());
  best.bone.assign(triangle_count, 0);
  memory.hold(best.bytes());
  stats.assignment_ms = ms_since(assignment_start);

  // As many bones per chunk as the budget allows, at least one.
  const std::size_t bytes_per_bone = std::max<std::size_t>(vertex_count * sizeof(Aabb), 1);
  const std::uint32_t chunk_bones = static_cast<std::uint32_t>(
      std::clamp<std::size_t>(options.memory_budget_bytes / bytes_per_bone, 1, bone_count));
  const std::uint32_t chunk_count = (bone_count + chunk_bones - 1) / chunk_bones;
  const std::uint32_t clusters_per_bone =
      options.pose_clusters == 0 && options.fine_mesh_clusters && triangle_count >= kFineMeshTriangles
          ? kFineMeshPoseClusters
          : options.pose_clusters;
  const std::uint32_t sweeps = chunk_count + 1 + (clusters_per_bone > 0 ? 1 : 0);
  Progress progress(options, static_cast<double>(samples.count()) * sweeps);

  SINEW_RETURN_IF_ERROR(
      assign_in_chunks(samples, candidates, needs, chunk_bones, pad, jobs, progress, memory, best, stats));
  memory.release(candidates.bytes() + needs.bytes() + best.bytes());
  candidates = BoneLists{};
  needs = BoneLists{};
  out.triangle_bone = std::move(best.bone);
  best = Assignment{};
  memory.hold(bytes_of(out.triangle_bone));

  // The escape checks: the vertex boxes of the chosen bones.
  assignment_start = Clock::now();
  make_vertex_checks(adj, out.triangle_bone, vertex_count, out);
  memory.hold(bytes_of(out.vertex_checks) + bytes_of(out.vertex_check_begin));
  memory.release(adj.bytes());
  adj = VertexTriangles{};
  stats.assignment_ms += ms_since(assignment_start);
  sampling_start = Clock::now();
  SINEW_RETURN_IF_ERROR(grow_check_boxes(samples, pad, jobs, progress, out));
  stats.sampling_ms += ms_since(sampling_start);
  ClusterMembers cluster_members;
  if (clusters_per_bone > 0) {
    const auto clustering_start = Clock::now();
    const float scale = padding_distance(mesh, 1.0f);
    cluster_members = plan_clusters(samples, clusters_per_bone, scale > 0.0f ? scale : 1.0f, jobs, out);
    SINEW_RETURN_IF_ERROR(grow_cluster_boxes(samples, cluster_members, pad, jobs, progress, out));
    memory.hold(bytes_of(out.cluster_boxes) + bytes_of(out.check_rank));
    stats.clustering_ms = ms_since(clustering_start);
    stats.clusters_per_bone = clusters_per_bone;
  }
  memory.release(bytes_of(inverses));
  inverses = std::vector<Affine3>{};  // `samples` is not used past this point
  assignment_start = Clock::now();
  link_triangle_checks(mesh, out);
  const std::vector<Aabb> triangle_boxes = triangle_fuzzy_boxes(out);
  memory.hold(bytes_of(out.triangle_checks) + bytes_of(triangle_boxes));
  for (const Aabb& box : triangle_boxes) stats.fuzzy_area += surface_area_d(box);
  stats.rest_area = rest_area(mesh);
  stats.assignment_ms += ms_since(assignment_start);

  // The per-bone trees (their builders' own memory is not counted).
  SINEW_RETURN_IF_ERROR(progress.report("build", kSweepShare));
  const auto build_start = Clock::now();
  SINEW_RETURN_IF_ERROR(build_bone_trees(triangle_boxes, options, jobs, out));
  if (clusters_per_bone > 0) {
    SINEW_RETURN_IF_ERROR(build_cluster_trees(mesh, tree_build_options(options, triangle_count), jobs, out));
  }
  memory.hold(bytes_of(out.nodes) + bytes_of(out.items) + bytes_of(out.bone_trees));
  stats.build_ms = ms_since(build_start);
  stats.peak_bytes = memory.peak();
  SINEW_RETURN_IF_ERROR(progress.report("build", 1.0));
  return out;
}

}  // namespace sinew::rt
