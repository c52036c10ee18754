#include "raytrace/scene/ray_reach.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sinew::rt {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Clips [t0, t1] to the slab test of o + t d against [lower, upper]; false
// when the segment misses.
bool clip(const double o[3], const double d[3], const double lower[3], const double upper[3], double& t0,
          double& t1) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lower[a] || o[a] > upper[a]) return false;
      continue;
    }
    double lo = (lower[a] - o[a]) / d[a], hi = (upper[a] - o[a]) / d[a];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  return t0 <= t1;
}

void corners(const Aabb& box, double margin, double lower[3], double upper[3]) {
  for (int a = 0; a < 3; ++a) {
    lower[a] = static_cast<double>(box.lower[a]) - margin;
    upper[a] = static_cast<double>(box.upper[a]) + margin;
  }
}

}  // namespace

Status RayReach::mark(std::span<const Ray> rays, std::span<const Aabb> boxes, double margin,
                      std::vector<std::uint8_t>& reached) {
  reached.assign(boxes.size(), 0);
  if (rays.empty() || boxes.empty()) return {};
  // The tree's cells hold the boxes grown by the margin (in float, outward).
  const float grow = std::nextafter(static_cast<float>(margin), std::numeric_limits<float>::infinity());
  grown_.resize(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    grown_[i] = boxes[i].is_empty() ? Aabb::empty() : Aabb{boxes[i].lower - Vec3(grow), boxes[i].upper + Vec3(grow)};
  }
  SINEW_ASSIGN_OR_RETURN(tree_, build_kd_tree(grown_));
  if (tree_.nodes.empty()) return {};
  double root_lower[3], root_upper[3];
  corners(tree_.bounds, margin, root_lower, root_upper);

  struct Entry {
    std::uint32_t node;
    double t0, t1;
  };
  std::array<Entry, kMaxTraversalDepth + 2> stack;
  for (const Ray& ray : rays) {
    if (!finite(ray.origin) || !finite(ray.direction) || std::isnan(ray.t_min) || std::isnan(ray.t_max)) {
      for (std::size_t i = 0; i < boxes.size(); ++i) reached[i] = boxes[i].is_empty() ? 0 : 1;
      return {};
    }
    const double o[3] = {static_cast<double>(ray.origin.x), static_cast<double>(ray.origin.y),
                         static_cast<double>(ray.origin.z)};
    const double d[3] = {static_cast<double>(ray.direction.x), static_cast<double>(ray.direction.y),
                         static_cast<double>(ray.direction.z)};
    double t0 = static_cast<double>(ray.t_min), t1 = static_cast<double>(ray.t_max);
    if (!clip(o, d, root_lower, root_upper, t0, t1)) continue;
    std::size_t top = 0;
    stack[top++] = {0, t0, t1};
    while (top > 0) {
      const Entry entry = stack[--top];
      const KdNode& node = tree_.nodes[entry.node];
      if (node.is_leaf()) {
        for (std::uint32_t k = 0; k < node.item_count(); ++k) {
          const std::uint32_t item = tree_.items[node.first_item() + k];
          if (reached[item]) continue;
          double lower[3], upper[3];
          corners(boxes[item], margin, lower, upper);
          double s0 = static_cast<double>(ray.t_min), s1 = static_cast<double>(ray.t_max);
          if (clip(o, d, lower, upper, s0, s1)) reached[item] = 1;
        }
        continue;
      }
      // Both children whose side of the plane, thickened by the margin, the
      // segment passes.
      const int a = node.axis();
      const double split = static_cast<double>(node.split());
      const std::uint32_t below = entry.node + 1, above = node.above_child();
      if (top + 2 > stack.size()) {  // deeper than any tree built here: reach everything
        for (std::size_t i = 0; i < boxes.size(); ++i) reached[i] = boxes[i].is_empty() ? 0 : 1;
        return {};
      }
      if (d[a] == 0.0) {
        if (o[a] <= split + margin) stack[top++] = {below, entry.t0, entry.t1};
        if (o[a] >= split - margin) stack[top++] = {above, entry.t0, entry.t1};
        continue;
      }
      const double t_split = (split - o[a]) / d[a], dt = margin / std::fabs(d[a]);
      const bool forward = d[a] > 0.0;
      const Entry low = forward ? Entry{below, entry.t0, std::min(entry.t1, t_split + dt)}
                                : Entry{below, std::max(entry.t0, t_split - dt), entry.t1};
      const Entry high = forward ? Entry{above, std::max(entry.t0, t_split - dt), entry.t1}
                                 : Entry{above, entry.t0, std::min(entry.t1, t_split + dt)};
      if (low.t0 <= low.t1) stack[top++] = low;
      if (high.t0 <= high.t1) stack[top++] = high;
    }
  }
  return {};
}

}  // namespace sinew::rt
