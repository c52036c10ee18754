// Pose-space clusters (fuzzy bake, bake_steps.h; raytrace/fuzzy/
// pose_clusters.h): per bone its samples clustered by its feature, each
// cluster's check boxes over its samples alone, and a tree per cluster.
#include <algorithm>

#include "raytrace/bake/bake_steps.h"
#include "raytrace/fuzzy/pose_clusters.h"
#include "raytrace/skinning/skinning.h"

namespace sinew::rt::bake_detail {

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
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, "clusters", [&](Range r, std::size_t s0, std::size_t s1) {
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

}  // namespace sinew::rt::bake_detail
