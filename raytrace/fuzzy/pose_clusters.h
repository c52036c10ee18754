// Pose-space clusters of a bone (FuzzyBakeOptions::pose_clusters; the data
// is BoneCluster's, raytrace/fuzzy/fuzzy_character.h): the feature that
// tells a bone's poses apart, the bake's k-means over the samples, and the
// frame's choice of the nearest centre.
//
// The feature of bone b in a pose is, for each bone j weighting a vertex of
// b's triangles (its feature bones), the matrix S_b^-1 S_j: where b's
// vertices sit in b's frame depends on nothing else. A bone none of whose
// triangles' vertices another bone weights is rigid in its frame (its boxes
// are points) and gets no clusters.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::rt {

// Per bone its feature bones as CSR (begin has bone_count + 1 entries):
// the bones other than b weighting (non-zero) a vertex that has a check
// against b, ascending.
void cluster_feature_bones(const SkinnedMesh& mesh, std::span<const std::uint32_t> vertex_check_begin,
                           std::span<const VertexCheck> vertex_checks, std::uint32_t bone_count,
                           std::vector<std::uint32_t>& begin, std::vector<std::uint16_t>& bones);

// Bone b's feature in a pose: kClusterFeatureFloats per feature bone, written
// to `out`. `bone_from_pose` is S_b^-1, `pose` the skinning matrices.
void cluster_feature(const Affine3& bone_from_pose, std::span<const Affine3> pose,
                     std::span<const std::uint16_t> feature_bones, float translation_scale, float* out);

// Lloyd's k-means of `count` points of `dims` floats (row-major) into at
// most k clusters, seeded by farthest points from the point nearest the
// mean, so the result depends only on the points. Writes each point's
// cluster to `member` and the centres (dims floats each) to `centres`;
// returns the cluster count (empty clusters are dropped, so fewer than k
// when the points have fewer distinct values).
std::uint32_t cluster_points(std::span<const float> points, std::size_t count, std::size_t dims, std::uint32_t k,
                             std::vector<std::uint32_t>& member, std::vector<float>& centres);

// The cluster of `clusters` whose centre is nearest `feature` (squared
// distance; ties: the first), as an index into `clusters`; -1 when there are
// none or a distance is not finite.
int nearest_cluster(std::span<const BoneCluster> clusters, std::span<const float> centres,
                    std::span<const float> feature);

}  // namespace sinew::rt
