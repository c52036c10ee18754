#include "raytrace/scene/frame_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "raytrace/fuzzy/pose_clusters.h"
#include "runtime/jobs/job_system.h"

namespace sinew::rt {
namespace {

float max_abs(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

float max_abs(const Aabb& box) {
  return box.is_empty() ? 0.0f : std::max(max_abs(box.lower), max_abs(box.upper));
}

// The infinity norm of the linear part (largest row sum of |m_ij|): how much
// the transform can stretch a rounding error.
float linear_norm(const Affine3& m) {
  float norm = 0.0f;
  for (const Vec4& row : m.rows) {
    norm = std::max(norm, std::fabs(row.x) + std::fabs(row.y) + std::fabs(row.z));
  }
  return norm;
}

Aabb grown(const Aabb& box, float by) {
  if (box.is_empty()) return box;
  return {box.lower - Vec3(by), box.upper + Vec3(by)};
}

// The escape check of the frame's bones, each held to its cluster's boxes
// where it has one.
EscapeCheckInput escape_input(const InstanceFrame& frame, FrameScratch& scratch, const FuzzyCharacterView& fuzzy,
                              std::span<const std::uint16_t> rigid_blocks) {
  const bool clustered = frame.cluster_bones > 0 && frame.bone_check_boxes.size() == frame.bone_from_world.size();
  return {fuzzy.vertex_check_begin,
          fuzzy.vertex_checks,
          frame.bone_from_world,
          frame.tolerance,
          scratch.chunk_bone_boxes,
          clustered ? std::span<const Aabb* const>(frame.bone_check_boxes) : std::span<const Aabb* const>{},
          clustered ? fuzzy.check_rank : std::span<const std::uint32_t>{},
          rigid_blocks};
}

}  // namespace

InfluenceBounds influence_bounds(const SkinnedMesh& mesh, std::size_t bone_count) {
  InfluenceBounds out;
  out.bone_rest_boxes.assign(bone_count, Aabb::empty());
  const std::size_t vertices = std::min({mesh.positions.size(), mesh.joints.size(), mesh.weights.size()});
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t v = 0; v < vertices; ++v) {
    double sum = 0.0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
      const float w = mesh.weights[v][k];
      // The kernels skip a slot whose weight compares equal to zero.
      if (w == 0.0f) continue;
      sum += static_cast<double>(w);
      const std::size_t bone = mesh.joints[v][k];
      if (bone < bone_count) out.bone_rest_boxes[bone].extend(mesh.positions[v]);
    }
    lo = std::min(lo, sum);
    hi = std::max(hi, sum);
  }
  if (vertices > 0) {
    // Outward to float.
    out.weight_sum_lo = std::nextafter(static_cast<float>(lo), -std::numeric_limits<float>::infinity());
    out.weight_sum_hi = std::nextafter(static_cast<float>(hi), std::numeric_limits<float>::infinity());
    out.weight_sum_lo = std::max(out.weight_sum_lo, 0.0f);
  }
  return out;
}

Aabb instance_bounds(std::span<const Affine3> skinning, const InfluenceBounds& bounds) {
  Aabb carried = Aabb::empty();
  const std::size_t bones = std::min(skinning.size(), bounds.bone_rest_boxes.size());
  for (std::size_t b = 0; b < bones; ++b) {
    if (!bounds.bone_rest_boxes[b].is_empty()) carried.extend(transform(skinning[b], bounds.bone_rest_boxes[b]));
  }
  Aabb out = Aabb::empty();
  if (!carried.is_empty()) {
    // Weight sums in [lo, hi] scale the carried box per axis: the interval
    // product's ends.
    for (int a = 0; a < 3; ++a) {
      const float ends[4] = {bounds.weight_sum_lo * carried.lower[a], bounds.weight_sum_lo * carried.upper[a],
                             bounds.weight_sum_hi * carried.lower[a], bounds.weight_sum_hi * carried.upper[a]};
      out.lower[a] = std::min({ends[0], ends[1], ends[2], ends[3]});
      out.upper[a] = std::max({ends[0], ends[1], ends[2], ends[3]});
    }
    // Skinning sums a few weighted products per coordinate: its rounding is
    // a few units of 2^-24 of the largest, far inside this.
    out = grown(out, 64.0f * kFrameRelativeSlack * std::max(bounds.weight_sum_hi, 1.0f) * max_abs(carried) +
                         std::numeric_limits<float>::min());
  }
  // A vertex without weights skins to the origin.
  if (bounds.weight_sum_lo == 0.0f) out.extend(Vec3(0.0f));
  return out;
}

void update_bone_frames(InstanceFrame& frame, const FuzzyCharacterView& fuzzy) {
  const std::size_t bones = frame.skinning.size();
  frame.bone_from_world.resize(bones);
  frame.bone_usable.resize(bones);
  frame.tolerance.resize(bones);
  frame.bone_carry.resize(bones);
  frame.singular_bones = 0;
  for (std::size_t b = 0; b < bones; ++b) {
    const Affine3& to_world = frame.skinning[b];
    const Affine3 from_world = inverse(to_world);
    const bool usable = is_finite(from_world);
    frame.bone_from_world[b] = from_world;
    frame.bone_usable[b] = usable ? 1 : 0;
    if (!usable) {
      frame.tolerance[b] = 0.0f;
      frame.bone_carry[b] = {};
      if (fuzzy.bone_trees[b].triangle_count > 0) ++frame.singular_bones;
      continue;
    }
    // A skinned vertex near this bone has world coordinates up to `world`;
    // skinning it and carrying it back into the bone frame each round
    // relative to that magnitude (and to the inverse's translation, which
    // cancels against it far from the origin), stretched by the inverse.
    const Aabb& local = fuzzy.bone_trees[b].bounds;
    const float world = max_abs(transform(to_world, local));
    const float carried = linear_norm(from_world) * world + max_abs(from_world.translation_part());
    frame.tolerance[b] = kFrameRelativeSlack * (carried + max_abs(local));
    frame.bone_carry[b] = {linear_norm(from_world), max_abs(from_world.translation_part()), max_abs(local)};
  }
}

void choose_bone_clusters(InstanceFrame& frame, const FuzzyCharacterView& fuzzy, bool use) {
  const std::size_t bones = frame.skinning.size();
  frame.bone_cluster.assign(bones, -1);
  frame.bone_check_boxes.assign(bones, nullptr);
  frame.cluster_bones = 0;
  frame.cluster_misses = 0;
  if (!use || !fuzzy.has_clusters()) return;
  std::vector<float> feature;
  for (std::uint32_t b = 0; b < std::min<std::size_t>(bones, fuzzy.bone_count); ++b) {
    const std::span<const BoneCluster> clusters = fuzzy.bone_clusters(b);
    if (clusters.empty() || !frame.bone_usable[b]) continue;
    const std::span<const std::uint16_t> feature_bones = fuzzy.bone_feature_bones(b);
    feature.resize(feature_bones.size() * kClusterFeatureFloats);
    cluster_feature(frame.bone_from_world[b], frame.skinning, feature_bones, fuzzy.feature_translation_scale,
                    feature.data());
    const int k = nearest_cluster(clusters, fuzzy.cluster_centres, feature);
    if (k < 0) continue;
    const std::size_t q = fuzzy.bone_cluster_begin[b] + static_cast<std::size_t>(k);
    frame.bone_cluster[b] = static_cast<std::int32_t>(q);
    frame.bone_check_boxes[b] = fuzzy.cluster_boxes.data() + fuzzy.clusters[q].box_begin;
    ++frame.cluster_bones;
  }
}

void skin_instance(InstanceFrame& frame, FrameScratch& scratch, const SkinnedMesh& mesh,
                   const PackedInfluences& influences, const FuzzyCharacterView& fuzzy,
                   std::span<const std::uint16_t> rigid_blocks, bool normals, bool exact_boxes, SkinningPath path,
                   JobSystem& jobs) {
  frame.positions.resize(mesh.vertex_count());
  frame.normals.resize(normals && !mesh.normals.empty() ? mesh.vertex_count() : 0);
  scratch.escaped.resize(fuzzy.vertex_checks.size());
  scratch.chunk_bone_boxes.resize(exact_boxes ? skinning_chunk_count(mesh.vertex_count()) * frame.bone_from_world.size()
                                            : 0);
  const EscapeCheckInput escape = escape_input(frame, scratch, fuzzy, rigid_blocks);
  const SkinningTargets targets{frame.positions, frame.normals, scratch.escaped};
  const SkinningResult result = skin_vertices(mesh, influences, frame.skinning, targets, &escape, &jobs, path);
  frame.escaped_checks = result.escaped_checks;
}

void settle_bone_clusters(InstanceFrame& frame, FrameScratch& scratch, const FuzzyCharacterView& fuzzy,
                          std::span<const std::uint16_t> rigid_blocks, JobSystem& jobs) {
  if (frame.cluster_bones == 0 || frame.escaped_checks == 0) return;
  bool missed = false;
  const std::size_t checks = std::min(scratch.escaped.size(), fuzzy.vertex_checks.size());
  for (std::size_t c = 0; c < checks; ++c) {
    if (!scratch.escaped[c]) continue;
    const std::uint32_t b = fuzzy.vertex_checks[c].bone;
    if (b >= frame.bone_cluster.size() || frame.bone_cluster[b] < 0) continue;
    frame.bone_cluster[b] = -1;
    frame.bone_check_boxes[b] = nullptr;
    --frame.cluster_bones;
    ++frame.cluster_misses;
    missed = true;
  }
  if (!missed) return;
  frame.escaped_checks =
      check_escapes(escape_input(frame, scratch, fuzzy, rigid_blocks), frame.positions, scratch.escaped, &jobs);
}

void compute_bone_boxes(InstanceFrame& frame, const FrameScratch& scratch, const FuzzyCharacterView& fuzzy,
                        bool exact) {
  const std::size_t bones = frame.skinning.size();
  frame.bone_world_boxes.assign(bones, Aabb::empty());
  if (!exact) {
    for (std::size_t b = 0; b < bones; ++b) {
      if (!frame.bone_usable[b]) continue;
      const Aabb local = grown(frame.bone_tree(fuzzy, static_cast<std::uint32_t>(b)).bounds, frame.tolerance[b]);
      frame.bone_world_boxes[b] = transform(frame.skinning[b], local);
    }
    return;
  }
  // The vertex checks list, per vertex, exactly the bones whose triangles use
  // it: the boxes of each check's bone grown by its vertex, gathered per
  // chunk by the skinning (skin_instance), give every bone the bounds of its
  // skinned triangles, merged here in chunk order.
  const std::size_t stride = frame.bone_from_world.size();
  const std::size_t rows = stride > 0 ? scratch.chunk_bone_boxes.size() / stride : 0;
  for (std::size_t row = 0; row < rows; ++row) {
    for (std::size_t b = 0; b < std::min(bones, stride); ++b) {
      frame.bone_world_boxes[b].extend(scratch.chunk_bone_boxes[row * stride + b]);
    }
  }
  for (std::size_t b = 0; b < bones; ++b) {
    if (!frame.bone_usable[b]) frame.bone_world_boxes[b] = Aabb::empty();
  }
}

Status build_fallback(InstanceFrame& frame, const FrameScratch& scratch, const SkinnedMesh& mesh,
                      const FuzzyCharacterView& fuzzy, const KdBuildOptions& kd) {
  frame.escaped_triangles.clear();
  if (frame.escaped_checks == 0 && frame.singular_bones == 0) {
    frame.fallback = KdTree{};
    return {};
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& corners = fuzzy.triangle_checks[t];
    const bool escaped = !frame.bone_usable[fuzzy.triangle_bone[t]] || scratch.escaped[corners[0]] ||
                         scratch.escaped[corners[1]] || scratch.escaped[corners[2]];
    if (escaped) frame.escaped_triangles.push_back(static_cast<std::uint32_t>(t));
  }
  std::vector<Aabb> boxes;
  boxes.reserve(frame.escaped_triangles.size());
  for (const std::uint32_t t : frame.escaped_triangles) {
    Aabb box;
    for (const std::uint32_t v : mesh.triangles[t]) box.extend(frame.positions[v]);
    boxes.push_back(box);
  }
  SINEW_ASSIGN_OR_RETURN(frame.fallback, build_kd_tree(boxes, kd));
  return {};
}

}  // namespace sinew::rt
