// Candidate bones (fuzzy bake, bake_steps.h): which bones compete for each
// triangle, which (vertex, bone) boxes that takes, and which bones stand in
// for the ones that move rigidly with their parents.
#include <algorithm>
#include <array>

#include "raytrace/bake/bake_steps.h"

namespace sinew::rt::bake_detail {

std::vector<std::uint16_t> all_bones(std::uint32_t bone_count) {
  std::vector<std::uint16_t> bones(bone_count);
  for (std::uint32_t b = 0; b < bone_count; ++b) bones[b] = static_cast<std::uint16_t>(b);
  return bones;
}

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

std::vector<std::uint16_t> represented_bones(std::span<const std::uint16_t> rep) {
  std::vector<std::uint16_t> bones;
  for (std::size_t b = 0; b < rep.size(); ++b) {
    if (rep[b] == b) bones.push_back(static_cast<std::uint16_t>(b));
  }
  return bones;
}

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

}  // namespace sinew::rt::bake_detail
