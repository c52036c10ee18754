#include "raytrace/fuzzy/pose_clusters.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sinew::rt {
namespace {

// Lloyd iterations at most; a bone's samples settle in a handful.
constexpr int kMaxIterations = 32;

double squared_distance(const float* a, const float* b, std::size_t dims) {
  double sum = 0.0;
  for (std::size_t i = 0; i < dims; ++i) {
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    sum += d * d;
  }
  return sum;
}

}  // namespace

void cluster_feature_bones(const SkinnedMesh& mesh, std::span<const std::uint32_t> vertex_check_begin,
                           std::span<const VertexCheck> vertex_checks, std::uint32_t bone_count,
                           std::vector<std::uint32_t>& begin, std::vector<std::uint16_t>& bones) {
  // Per bone a bit per other bone: skeletons are small (tens of bones).
  std::vector<std::uint8_t> uses(static_cast<std::size_t>(bone_count) * bone_count, 0);
  const std::size_t vertices = std::min(mesh.vertex_count(), vertex_check_begin.size() - 1);
  for (std::size_t v = 0; v < vertices; ++v) {
    for (std::uint32_t c = vertex_check_begin[v]; c < vertex_check_begin[v + 1]; ++c) {
      const std::uint32_t b = vertex_checks[c].bone;
      for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
        if (mesh.weights[v][k] == 0.0f) continue;
        const std::uint32_t j = mesh.joints[v][k];
        if (j != b && j < bone_count && b < bone_count) uses[static_cast<std::size_t>(b) * bone_count + j] = 1;
      }
    }
  }
  begin.assign(1, 0);
  bones.clear();
  for (std::uint32_t b = 0; b < bone_count; ++b) {
    for (std::uint32_t j = 0; j < bone_count; ++j) {
      if (uses[static_cast<std::size_t>(b) * bone_count + j]) bones.push_back(static_cast<std::uint16_t>(j));
    }
    begin.push_back(static_cast<std::uint32_t>(bones.size()));
  }
}

void cluster_feature(const Affine3& bone_from_pose, std::span<const Affine3> pose,
                     std::span<const std::uint16_t> feature_bones, float translation_scale, float* out) {
  const float inv_scale = translation_scale > 0.0f ? 1.0f / translation_scale : 1.0f;
  for (const std::uint16_t j : feature_bones) {
    const Affine3 m = bone_from_pose * pose[j];
    for (const Vec4& row : m.rows) {
      *out++ = row.x;
      *out++ = row.y;
      *out++ = row.z;
      *out++ = row.w * inv_scale;
    }
  }
}

std::uint32_t cluster_points(std::span<const float> points, std::size_t count, std::size_t dims, std::uint32_t k,
                             std::vector<std::uint32_t>& member, std::vector<float>& centres) {
  member.assign(count, 0);
  centres.clear();
  if (count == 0 || dims == 0 || k == 0) return 0;
  const auto point = [&](std::size_t i) { return points.data() + i * dims; };
  // Seeds: the point nearest the mean, then each time the point farthest
  // from every seed so far (ties: the first), until k or no point is apart.
  std::vector<double> mean(dims, 0.0);
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t d = 0; d < dims; ++d) mean[d] += static_cast<double>(point(i)[d]);
  }
  std::vector<float> mean_f(dims);
  for (std::size_t d = 0; d < dims; ++d) mean_f[d] = static_cast<float>(mean[d] / static_cast<double>(count));
  std::size_t first = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < count; ++i) {
    const double dist = squared_distance(point(i), mean_f.data(), dims);
    if (dist < best) {
      best = dist;
      first = i;
    }
  }
  centres.insert(centres.end(), point(first), point(first) + dims);
  std::vector<double> nearest(count, std::numeric_limits<double>::infinity());
  std::uint32_t clusters = 1;
  while (clusters < k) {
    const float* last = centres.data() + (clusters - 1) * dims;
    std::size_t far = 0;
    double far_dist = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      nearest[i] = std::min(nearest[i], squared_distance(point(i), last, dims));
      if (nearest[i] > far_dist) {
        far_dist = nearest[i];
        far = i;
      }
    }
    if (!(far_dist > 0.0)) break;  // every point is a seed already
    centres.insert(centres.end(), point(far), point(far) + dims);
    ++clusters;
  }
  // Lloyd: assign to the nearest centre, move each centre to its mean; and
  // a last assignment to the final centres, so each point's cluster is the
  // one nearest_cluster picks for it (a sampled pose always finds the boxes
  // grown from it).
  const auto assign = [&] {
    bool moved = false;
    for (std::size_t i = 0; i < count; ++i) {
      std::uint32_t to = 0;
      double to_dist = std::numeric_limits<double>::infinity();
      for (std::uint32_t c = 0; c < clusters; ++c) {
        const double dist = squared_distance(point(i), centres.data() + c * dims, dims);
        if (dist < to_dist) {
          to_dist = dist;
          to = c;
        }
      }
      moved = moved || member[i] != to;
      member[i] = to;
    }
    return moved;
  };
  std::vector<double> sums(static_cast<std::size_t>(clusters) * dims);
  std::vector<std::size_t> sizes(clusters);
  assign();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    std::fill(sums.begin(), sums.end(), 0.0);
    std::fill(sizes.begin(), sizes.end(), 0);
    for (std::size_t i = 0; i < count; ++i) {
      ++sizes[member[i]];
      for (std::size_t d = 0; d < dims; ++d) sums[member[i] * dims + d] += static_cast<double>(point(i)[d]);
    }
    for (std::uint32_t c = 0; c < clusters; ++c) {
      if (sizes[c] == 0) continue;  // keeps its centre; dropped below if it stays empty
      for (std::size_t d = 0; d < dims; ++d) {
        centres[c * dims + d] = static_cast<float>(sums[c * dims + d] / static_cast<double>(sizes[c]));
      }
    }
    if (!assign()) break;
  }
  // Drop empty clusters, renumbering the rest in order.
  std::fill(sizes.begin(), sizes.end(), 0);
  for (std::size_t i = 0; i < count; ++i) ++sizes[member[i]];
  std::vector<std::uint32_t> renumber(clusters, 0);
  std::uint32_t kept = 0;
  for (std::uint32_t c = 0; c < clusters; ++c) {
    if (sizes[c] == 0) continue;
    renumber[c] = kept;
    std::copy_n(centres.begin() + static_cast<std::ptrdiff_t>(c * dims), dims,
                centres.begin() + static_cast<std::ptrdiff_t>(kept * dims));
    ++kept;
  }
  centres.resize(kept * dims);
  for (std::uint32_t& m : member) m = renumber[m];
  return kept;
}

int nearest_cluster(std::span<const BoneCluster> clusters, std::span<const float> centres,
                    std::span<const float> feature) {
  int best = -1;
  double best_dist = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const std::size_t at = clusters[c].centre_begin;
    if (at + feature.size() > centres.size()) return -1;
    const double dist = squared_distance(feature.data(), centres.data() + at, feature.size());
    if (!std::isfinite(dist)) return -1;
    if (dist < best_dist) {
      best_dist = dist;
      best = static_cast<int>(c);
    }
  }
  return best;
}

}  // namespace sinew::rt
