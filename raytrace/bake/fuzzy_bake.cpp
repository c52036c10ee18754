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
#include "raytrace/bake/fuzzy_bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "raytrace/fuzzy/pose_clusters.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/core/format_number.h"
#include "runtime/jobs/job_system.h"
#include "runtime/mesh/mesh_checks.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kMaxBones = 65535;     // triangle_bone is uint16
constexpr std::size_t kSamplesPerBatch = 8;  // samples swept per pass over the vertices
constexpr std::size_t kVertexGrain = 512;
constexpr std::size_t kTriangleGrain = 2048;
// Share of the progress fraction spent before the kd-tree builds start.
constexpr double kSweepShare = 0.9;

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

// Surface area in double: assignment compares areas of boxes that may differ
// only slightly, and the stats sum many of them.
double surface_area_d(const Aabb& box) {
  if (box.is_empty()) return 0.0;
  const double dx = static_cast<double>(box.upper.x) - static_cast<double>(box.lower.x);
  const double dy = static_cast<double>(box.upper.y) - static_cast<double>(box.lower.y);
  const double dz = static_cast<double>(box.upper.z) - static_cast<double>(box.lower.z);
  return 2.0 * (dx * dy + dy * dz + dz * dx);
}

void pad_box(Aabb& box, float pad) {
  if (box.is_empty()) return;
  box.lower -= Vec3(pad);
  box.upper += Vec3(pad);
}

template <typename T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
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

// ---------------------------------------------------------------------------
// Candidate bones

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

std::vector<std::uint16_t> all_bones(std::uint32_t bone_count) {
  std::vector<std::uint16_t> bones(bone_count);
  for (std::uint32_t b = 0; b < bone_count; ++b) bones[b] = static_cast<std::uint16_t>(b);
  return bones;
}

// The part of a sorted bone list inside [first, last).
std::span<const std::uint16_t> within(std::span<const std::uint16_t> list, std::uint32_t first,
                                      std::uint32_t last) {
  const auto lo = std::lower_bound(list.begin(), list.end(), first);
  const auto hi = std::lower_bound(lo, list.end(), last);
  return list.subspan(static_cast<std::size_t>(lo - list.begin()),
                      static_cast<std::size_t>(hi - lo));
}

// Which triangles use each vertex (CSR).
struct VertexTriangles {
  std::vector<std::uint32_t> begin;
  std::vector<std::uint32_t> triangles;

  std::span<const std::uint32_t> of(std::size_t v) const {
    return std::span<const std::uint32_t>(triangles).subspan(begin[v], begin[v + 1] - begin[v]);
  }
  std::size_t bytes() const { return bytes_of(begin) + bytes_of(triangles); }
};

VertexTriangles vertex_triangles(const SkinnedMesh& mesh) {
  VertexTriangles adj;
  adj.begin.assign(mesh.vertex_count() + 1, 0);
  for (const auto& tri : mesh.triangles) {
    for (std::uint32_t v : tri) ++adj.begin[v + 1];
  }
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) adj.begin[v + 1] += adj.begin[v];
  adj.triangles.resize(adj.begin.back());
  std::vector<std::uint32_t> cursor(adj.begin.begin(), adj.begin.end() - 1);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (std::uint32_t v : mesh.triangles[t]) adj.triangles[cursor[v]++] = static_cast<std::uint32_t>(t);
  }
  return adj;
}

// The bones standing for themselves (see moving_representatives).
std::vector<std::uint16_t> represented_bones(std::span<const std::uint16_t> rep) {
  std::vector<std::uint16_t> bones;
  for (std::size_t b = 0; b < rep.size(); ++b) {
    if (rep[b] == b) bones.push_back(static_cast<std::uint16_t>(b));
  }
  return bones;
}

// CandidateBones::kInfluencing: the bones weighting any corner, with their
// parents and children, each replaced by its representative.
BoneLists influencing_candidates(const SkinnedMesh& mesh, std::span<const int> parents,
                                 std::span<const std::uint16_t> rep) {
  const std::uint32_t bone_count = static_cast<std::uint32_t>(rep.size());
  BoneLists children;  // per bone its children
  {
    std::vector<std::vector<std::uint16_t>> lists(bone_count);
    for (std::uint32_t b = 0; b < bone_count; ++b) {
      if (parents[b] >= 0) lists[static_cast<std::size_t>(parents[b])].push_back(static_cast<std::uint16_t>(b));
    }
    children.begin.push_back(0);
    for (auto& list : lists) children.append(list);
  }
  BoneLists candidates;
  candidates.begin.reserve(mesh.triangle_count() + 1);
  candidates.begin.push_back(0);
  std::vector<std::uint16_t> scratch;
  const std::vector<std::uint16_t> every_candidate = represented_bones(rep);
  for (const auto& tri : mesh.triangles) {
    scratch.clear();
    for (std::uint32_t v : tri) {
      for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
        if (mesh.weights[v][k] == 0.0f) continue;
        const std::uint16_t bone = mesh.joints[v][k];
        scratch.push_back(rep[bone]);
        if (parents[bone] >= 0) scratch.push_back(rep[static_cast<std::size_t>(parents[bone])]);
        for (std::uint16_t child : children.of(bone)) scratch.push_back(rep[child]);
      }
    }
    // Corners without any weight skin to the origin in every pose: no bone
    // is related to them, so let every bone compete.
    if (scratch.empty()) scratch = every_candidate;
    candidates.append(scratch);
  }
  return candidates;
}

// The bones each vertex needs a box in: the union of its triangles' candidates.
BoneLists vertex_needs(const VertexTriangles& adj, const BoneLists& triangle_candidates,
                       std::size_t vertex_count) {
  BoneLists needs;
  needs.begin.reserve(vertex_count + 1);
  needs.begin.push_back(0);
  std::vector<std::uint16_t> scratch;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    scratch.clear();
    for (std::uint32_t t : adj.of(v)) {
      const auto list = triangle_candidates.of(t);
      scratch.insert(scratch.end(), list.begin(), list.end());
    }
    needs.append(scratch);
  }
  return needs;
}

// ---------------------------------------------------------------------------
// Progress

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
// Sampling

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

// A bone that moves rigidly with its parent in every sample bounds its
// triangles no more tightly than the parent's frame does (up to the turn of
// its axes), yet costs a tree, a top-level object and a ray transform per
// instance and frame. Each bone's representative is itself, or, for such a
// bone, its parent's representative. "Rigidly": the relative transform
// (parent's bind-to-pose inverse times the bone's) moves no corner of the
// bind-pose bounds by more than kRigidTolerance of their diagonal from where
// the first sample puts it. Only tightness hangs on the tolerance: whichever
// bone a triangle gets, its boxes come from every sample in that frame.
constexpr double kRigidTolerance = 1e-4;

std::vector<std::uint16_t> moving_representatives(const Samples& samples, std::span<const int> parents) {
  const std::uint32_t bones = samples.bone_count;
  std::vector<std::uint16_t> rep(bones);
  Aabb bind;
  for (const Vec3& p : samples.mesh.positions) bind.extend(p);
  std::array<Vec3, 8> corners{};
  double tolerance = 0.0;
  if (!bind.is_empty()) {
    for (int c = 0; c < 8; ++c) {
      corners[static_cast<std::size_t>(c)] = Vec3((c & 1) ? bind.upper.x : bind.lower.x,
                                                  (c & 2) ? bind.upper.y : bind.lower.y,
                                                  (c & 4) ? bind.upper.z : bind.lower.z);
    }
    tolerance = kRigidTolerance * static_cast<double>(glm::length(bind.extent()));
  }
  // Parents come before their children (the skeleton's sorted order), so a
  // parent's representative is known when its child is reached.
  for (std::uint32_t b = 0; b < bones; ++b) {
    rep[b] = static_cast<std::uint16_t>(b);
    const int parent = parents[b];
    if (parent < 0 || static_cast<std::uint32_t>(parent) >= b || bind.is_empty()) continue;
    bool rigid = true;
    std::array<Vec3, 8> first{};
    for (std::size_t s = 0; s < samples.count() && rigid; ++s) {
      const Affine3 relative = samples.bone_from_pose(s)[parent] * samples.pose(s)[b];
      for (std::size_t c = 0; c < corners.size() && rigid; ++c) {
        const Vec3 moved = relative.transform_point(corners[c]);
        if (s == 0) {
          first[c] = moved;
        } else {
          rigid = static_cast<double>(glm::length(moved - first[c])) <= tolerance;
        }
      }
    }
    if (rigid) rep[b] = rep[static_cast<std::size_t>(parent)];
  }
  return rep;
}

// Calls grow(vertices, first_sample, last_sample) over all vertices for
// batches of samples, reporting progress between batches.
Status sweep_samples(const Samples& samples, JobSystem& jobs, Progress& progress,
                     const std::function<void(Range, std::size_t, std::size_t)>& grow) {
  const std::size_t count = samples.count();
  const std::size_t vertex_count = samples.mesh.vertex_count();
  for (std::size_t s0 = 0; s0 < count; s0 += kSamplesPerBatch) {
    const std::size_t s1 = std::min(count, s0 + kSamplesPerBatch);
    jobs.parallel_for(0, vertex_count, kVertexGrain, [&](Range r) { grow(r, s0, s1); });
    SINEW_RETURN_IF_ERROR(progress.advance("sampling", static_cast<double>(s1 - s0)));
  }
  return {};
}

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

Status grow_chunk_boxes(const Samples& samples, const BoneLists& needs, BoxChunk& chunk, float pad,
                        JobSystem& jobs, Progress& progress) {
  std::fill(chunk.boxes.begin(), chunk.boxes.end(), Aabb::empty());
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, [&](Range r, std::size_t s0, std::size_t s1) {
    for (std::size_t v = r.begin; v < r.end; ++v) {
      const auto bones = within(needs.of(v), chunk.first, chunk.last);
      if (bones.empty()) continue;
      Aabb* boxes = &chunk.at(v, chunk.first);
      for (std::size_t s = s0; s < s1; ++s) {
        const Vec3 p = skin_point(samples.mesh, v, samples.pose(s));
        const Affine3* bone_from_pose = samples.bone_from_pose(s);
        for (std::uint16_t b : bones) boxes[b - chunk.first].extend(bone_from_pose[b].transform_point(p));
      }
    }
  }));
  jobs.parallel_for(0, chunk.boxes.size(), kVertexGrain * 4, [&](Range r) {
    for (std::size_t i = r.begin; i < r.end; ++i) pad_box(chunk.boxes[i], pad);
  });
  return {};
}

struct Assignment {
  std::vector<double> area;          // the best candidate's fuzzy box area so far
  std::vector<std::uint16_t> bone;   // the best candidate so far
  std::size_t bytes() const { return bytes_of(area) + bytes_of(bone); }
};

// Candidates are visited in increasing bone order (chunks in order, sorted
// lists within), so the strict comparison leaves ties with the lowest bone.
void assign_chunk(const SkinnedMesh& mesh, const BoneLists& candidates, const BoxChunk& chunk,
                  Assignment& best, JobSystem& jobs) {
  jobs.parallel_for(0, mesh.triangle_count(), kTriangleGrain, [&](Range r) {
    for (std::size_t t = r.begin; t < r.end; ++t) {
      const auto& tri = mesh.triangles[t];
      for (std::uint16_t b : within(candidates.of(t), chunk.first, chunk.last)) {
        Aabb box = chunk.at(tri[0], b);
        box.extend(chunk.at(tri[1], b));
        box.extend(chunk.at(tri[2], b));
        const double area = surface_area_d(box);
        if (area < best.area[t]) {
          best.area[t] = area;
          best.bone[t] = b;
        }
      }
    }
  });
}

// ---------------------------------------------------------------------------
// Escape checks

// One check per distinct bone among each vertex's triangles, sorted by bone.
void make_vertex_checks(const VertexTriangles& adj, std::span<const std::uint16_t> triangle_bone,
                        std::size_t vertex_count, FuzzyCharacterData& out) {
  out.vertex_check_begin.assign(1, 0);
  out.vertex_check_begin.reserve(vertex_count + 1);
  std::vector<std::uint16_t> scratch;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    scratch.clear();
    for (std::uint32_t t : adj.of(v)) scratch.push_back(triangle_bone[t]);
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    for (std::uint16_t b : scratch) out.vertex_checks.push_back({b, Aabb::empty()});
    out.vertex_check_begin.push_back(static_cast<std::uint32_t>(out.vertex_checks.size()));
  }
}

Status grow_check_boxes(const Samples& samples, float pad, JobSystem& jobs, Progress& progress,
                        FuzzyCharacterData& out) {
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, [&](Range r, std::size_t s0, std::size_t s1) {
    for (std::size_t v = r.begin; v < r.end; ++v) {
      VertexCheck* first = out.vertex_checks.data() + out.vertex_check_begin[v];
      VertexCheck* last = out.vertex_checks.data() + out.vertex_check_begin[v + 1];
      if (first == last) continue;
      for (std::size_t s = s0; s < s1; ++s) {
        const Vec3 p = skin_point(samples.mesh, v, samples.pose(s));
        const Affine3* bone_from_pose = samples.bone_from_pose(s);
        for (VertexCheck* c = first; c != last; ++c) c->box.extend(bone_from_pose[c->bone].transform_point(p));
      }
    }
  }));
  for (VertexCheck& c : out.vertex_checks) pad_box(c.box, pad);
  return {};
}

void link_triangle_checks(const SkinnedMesh& mesh, FuzzyCharacterData& out) {
  out.triangle_checks.resize(mesh.triangle_count());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint16_t bone = out.triangle_bone[t];
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.triangles[t][i];
      const auto first = out.vertex_checks.begin() + out.vertex_check_begin[v];
      const auto last = out.vertex_checks.begin() + out.vertex_check_begin[v + 1];
      const auto it = std::lower_bound(first, last, bone,
                                       [](const VertexCheck& c, std::uint16_t b) { return c.bone < b; });
      out.triangle_checks[t][i] = static_cast<std::uint32_t>(it - out.vertex_checks.begin());
    }
  }
}

std::vector<Aabb> triangle_fuzzy_boxes(const FuzzyCharacterData& out) {
  std::vector<Aabb> boxes(out.triangle_checks.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) {
    for (std::uint32_t c : out.triangle_checks[t]) boxes[t].extend(out.vertex_checks[c].box);
  }
  return boxes;
}

// ---------------------------------------------------------------------------
// Bone trees

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

// ---------------------------------------------------------------------------
// Pose-space clusters

// Per bone, each sample's cluster (empty for a bone without clusters).
using ClusterMembers = std::vector<std::vector<std::uint32_t>>;

// Clusters each bone's samples by its feature and lays out the clusters,
// their centres and the check ranks; the boxes are grown by
// grow_cluster_boxes and the trees built by build_cluster_trees.
ClusterMembers plan_clusters(const Samples& samples, std::uint32_t clusters_per_bone, float translation_scale,
                             JobSystem& jobs, FuzzyCharacterData& out) {
  const std::uint32_t bone_count = out.bone_count;
  cluster_feature_bones(samples.mesh, out.vertex_check_begin, out.vertex_checks, bone_count, out.feature_bone_begin,
                        out.feature_bones);
  out.feature_translation_scale = translation_scale;
  std::vector<std::uint32_t> triangles(bone_count, 0);
  for (const std::uint16_t b : out.triangle_bone) ++triangles[b];
  // A box per cluster only for the checks whose vertex another bone moves
  // (about half at 855,552 triangles); the others keep their full box.
  std::vector<std::uint32_t> checks(bone_count, 0);
  out.check_rank.assign(out.vertex_checks.size(), kSharedCheckBox);
  const SkinnedMesh& mesh = samples.mesh;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (std::uint32_t c = out.vertex_check_begin[v]; c < out.vertex_check_begin[v + 1]; ++c) {
      const std::uint32_t b = out.vertex_checks[c].bone;
      bool moved_by_another = false;
      for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
        moved_by_another = moved_by_another || (mesh.weights[v][k] != 0.0f && mesh.joints[v][k] != b);
      }
      if (moved_by_another) out.check_rank[c] = checks[b]++;
    }
  }

  // Per bone: k-means over its samples' features (bones in parallel).
  ClusterMembers members(bone_count);
  std::vector<std::vector<float>> centres(bone_count);
  std::vector<std::uint32_t> counts(bone_count, 0);
  const std::size_t sample_count = samples.count();
  jobs.parallel_for(0, bone_count, 1, [&](Range r) {
    for (std::size_t b = r.begin; b < r.end; ++b) {
      const std::span<const std::uint16_t> feature_bones(
          out.feature_bones.data() + out.feature_bone_begin[b], out.feature_bone_begin[b + 1] - out.feature_bone_begin[b]);
      if (triangles[b] == 0 || feature_bones.empty()) continue;
      const std::size_t dims = feature_bones.size() * kClusterFeatureFloats;
      std::vector<float> features(sample_count * dims);
      for (std::size_t s = 0; s < sample_count; ++s) {
        cluster_feature(samples.bone_from_pose(s)[b], samples.pose(s), feature_bones, translation_scale,
                        features.data() + s * dims);
      }
      counts[b] = cluster_points(features, sample_count, dims, clusters_per_bone, members[b], centres[b]);
      // One cluster is the full tree again.
      if (counts[b] < 2) {
        counts[b] = 0;
        members[b].clear();
      }
    }
  });
  out.bone_cluster_begin.assign(1, 0);
  std::size_t boxes = 0;
  for (std::uint32_t b = 0; b < bone_count; ++b) {
    const std::size_t dims = (out.feature_bone_begin[b + 1] - out.feature_bone_begin[b]) * kClusterFeatureFloats;
    for (std::uint32_t k = 0; k < counts[b]; ++k) {
      BoneCluster cluster;
      cluster.box_begin = static_cast<std::uint32_t>(boxes);
      cluster.centre_begin = static_cast<std::uint32_t>(out.cluster_centres.size());
      out.cluster_centres.insert(out.cluster_centres.end(), centres[b].begin() + static_cast<std::ptrdiff_t>(k * dims),
                                 centres[b].begin() + static_cast<std::ptrdiff_t>((k + 1) * dims));
      boxes += checks[b];
      out.clusters.push_back(cluster);
    }
    out.bone_cluster_begin.push_back(static_cast<std::uint32_t>(out.clusters.size()));
  }
  out.cluster_boxes.assign(boxes, Aabb::empty());
  return members;
}

// Each cluster's boxes of its bone's checks: the check's vertex over the
// cluster's samples, in the bone's frame (grow_check_boxes over a subset).
Status grow_cluster_boxes(const Samples& samples, const ClusterMembers& members, float pad, JobSystem& jobs,
                          Progress& progress, FuzzyCharacterData& out) {
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, [&](Range r, std::size_t s0, std::size_t s1) {
    for (std::size_t v = r.begin; v < r.end; ++v) {
      const std::uint32_t first = out.vertex_check_begin[v], last = out.vertex_check_begin[v + 1];
      bool clustered = false;
      for (std::uint32_t c = first; c < last; ++c) {
        clustered = clustered || (!members[out.vertex_checks[c].bone].empty() && out.check_rank[c] != kSharedCheckBox);
      }
      if (!clustered) continue;
      for (std::size_t s = s0; s < s1; ++s) {
        const Vec3 p = skin_point(samples.mesh, v, samples.pose(s));
        const Affine3* bone_from_pose = samples.bone_from_pose(s);
        for (std::uint32_t c = first; c < last; ++c) {
          const std::uint32_t b = out.vertex_checks[c].bone;
          if (members[b].empty() || out.check_rank[c] == kSharedCheckBox) continue;
          const BoneCluster& cluster = out.clusters[out.bone_cluster_begin[b] + members[b][s]];
          out.cluster_boxes[cluster.box_begin + out.check_rank[c]].extend(bone_from_pose[b].transform_point(p));
        }
      }
    }
  }));
  for (Aabb& box : out.cluster_boxes) pad_box(box, pad);
  return {};
}

// A tree per cluster over its bone's triangles and their cluster boxes,
// appended after the full trees; and the clusters' fuzzy area.
Status build_cluster_trees(const SkinnedMesh& mesh, const TreeBuild& build, JobSystem& jobs,
                           FuzzyCharacterData& out) {
  const std::uint32_t bone_count = out.bone_count;
  std::vector<std::vector<std::uint32_t>> bone_triangles(bone_count);
  for (std::size_t t = 0; t < out.triangle_bone.size(); ++t) {
    bone_triangles[out.triangle_bone[t]].push_back(static_cast<std::uint32_t>(t));
  }
  const FuzzyCharacterView view = out.view();
  const auto cluster_box = [&](const BoneCluster& cluster, std::uint32_t t) {
    Aabb box;
    for (const std::uint32_t c : out.triangle_checks[t]) box.extend(view.cluster_check_box(cluster, c));
    return box;
  };
  std::vector<std::uint32_t> cluster_bone(out.clusters.size());
  for (std::uint32_t b = 0; b < bone_count; ++b) {
    for (std::uint32_t q = out.bone_cluster_begin[b]; q < out.bone_cluster_begin[b + 1]; ++q) cluster_bone[q] = b;
  }
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::optional<BuiltTree>> trees,
                         build_trees(out.clusters.size(), build, jobs, [&](std::size_t q, std::vector<Aabb>& boxes) {
                           for (const std::uint32_t t : bone_triangles[cluster_bone[q]]) {
                             boxes.push_back(cluster_box(out.clusters[q], t));
                           }
                         }));
  for (std::size_t q = 0; q < out.clusters.size(); ++q) {
    BoneTree& bt = out.clusters[q].tree;
    const std::vector<std::uint32_t>& triangles = bone_triangles[cluster_bone[q]];
    bt.triangle_count = static_cast<std::uint32_t>(triangles.size());
    append_tree(*trees[q], triangles, out, bt);
  }
  // Each triangle's area averaged over its bone's clusters.
  double area = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint16_t b = out.triangle_bone[t];
    const std::uint32_t first = out.bone_cluster_begin[b], last = out.bone_cluster_begin[b + 1];
    if (first == last) {
      Aabb box;
      for (const std::uint32_t c : out.triangle_checks[t]) box.extend(out.vertex_checks[c].box);
      area += surface_area_d(box);
      continue;
    }
    double sum = 0.0;
    for (std::uint32_t q = first; q < last; ++q) sum += surface_area_d(cluster_box(out.clusters[q], static_cast<std::uint32_t>(t)));
    area += sum / static_cast<double>(last - first);
  }
  out.stats.cluster_fuzzy_area = area;
  out.stats.cluster_count = static_cast<std::uint32_t>(out.clusters.size());
  out.stats.node_count = tree_node_count(out);
  return {};
}

double rest_area(const SkinnedMesh& mesh) {
  double sum = 0.0;
  for (const auto& tri : mesh.triangles) {
    Aabb box;
    for (std::uint32_t v : tri) box.extend(mesh.positions[v]);
    sum += surface_area_d(box);
  }
  return sum;
}

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

  {
    BoxChunk chunk;
    chunk.boxes.resize(vertex_count * chunk_bones);
    memory.hold(bytes_of(chunk.boxes));
    for (std::uint32_t first = 0; first < bone_count; first += chunk_bones) {
      chunk.first = first;
      chunk.last = std::min(bone_count, first + chunk_bones);
      sampling_start = Clock::now();
      SINEW_RETURN_IF_ERROR(grow_chunk_boxes(samples, needs, chunk, pad, jobs, progress));
      stats.sampling_ms += ms_since(sampling_start);
      assignment_start = Clock::now();
      assign_chunk(mesh, candidates, chunk, best, jobs);
      stats.assignment_ms += ms_since(assignment_start);
      SINEW_RETURN_IF_ERROR(progress.advance("assignment", 0.0));
    }
    memory.release(bytes_of(chunk.boxes));
  }
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
