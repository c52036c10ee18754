// Binned SAH BVH builder (raytrace/accel/box_bvh.h).
//
// Each node bins its boxes' centres into `bins` equal slots per axis, sweeps
// the slots once from each side for the boxes' union areas and counts, and
// splits between the two slots of least cost area(left) * n(left) +
// area(right) * n(right) (the traversal cost is the same for every split,
// so it drops out; a node over max_leaf_items always splits). Where every
// centre falls in one slot on every axis, or past kBvhSahDepth, it splits at
// the median centre of the widest axis instead (ties by box index), which
// always separates and halves.
#include "raytrace/accel/box_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace sinew::rt {
namespace {

struct Builder {
  std::span<const Aabb> boxes;
  std::vector<Vec3> centres;
  BvhBuildOptions options;
  BoxBvh out;

  // Fills nodes[node] over ids[begin, end) (reordered in place).
  void build(std::uint32_t node, std::vector<std::uint32_t>& ids, std::size_t begin, std::size_t end, int depth) {
    Aabb box, centre_box;
    for (std::size_t i = begin; i < end; ++i) {
      box.extend(boxes[ids[i]]);
      centre_box.extend(centres[ids[i]]);
    }
    out.nodes[node].box = box;
    out.stats.max_depth = std::max(out.stats.max_depth, depth);
    const std::size_t n = end - begin;
    if (n <= static_cast<std::size_t>(options.max_leaf_items)) {
      make_leaf(node, ids, begin, end);
      return;
    }
    std::size_t mid = depth < kBvhSahDepth ? sah_split(ids, begin, end, centre_box) : begin;
    if (mid == begin) mid = median_split(ids, begin, end, centre_box);
    const std::uint32_t first = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.emplace_back();
    out.nodes.emplace_back();
    out.nodes[node].first = first;
    out.nodes[node].count = 0;
    build(first, ids, begin, mid, depth + 1);
    build(first + 1, ids, mid, end, depth + 1);
  }

  void make_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids, std::size_t begin, std::size_t end) {
    const auto first = ids.begin() + static_cast<std::ptrdiff_t>(begin);
    const auto last = ids.begin() + static_cast<std::ptrdiff_t>(end);
    std::sort(first, last);
    out.nodes[node].first = static_cast<std::uint32_t>(out.items.size());
    out.nodes[node].count = static_cast<std::uint32_t>(end - begin);
    out.items.insert(out.items.end(), first, last);
    ++out.stats.leaf_count;
  }

  // The slot of centre c on axis a of `centre_box` cut into `bins`.
  int slot(float c, int a, const Aabb& centre_box, float scale) const {
    const int s = static_cast<int>((c - centre_box.lower[a]) * scale);
    return std::clamp(s, 0, options.bins - 1);
  }

  // The SAH's partition point in ids[begin, end), or `begin` when no slot
  // boundary separates the centres.
  std::size_t sah_split(std::vector<std::uint32_t>& ids, std::size_t begin, std::size_t end, const Aabb& centre_box) {
    const int bins = options.bins;
    std::vector<Aabb> slot_box(static_cast<std::size_t>(bins));
    std::vector<std::size_t> slot_count(static_cast<std::size_t>(bins));
    std::vector<double> right_area(static_cast<std::size_t>(bins));
    std::vector<std::size_t> right_count(static_cast<std::size_t>(bins));
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_slot = 0;
    for (int a = 0; a < 3; ++a) {
      const float extent = centre_box.upper[a] - centre_box.lower[a];
      if (!(extent > 0.0f)) continue;
      const float scale = static_cast<float>(bins) / extent;
      std::fill(slot_box.begin(), slot_box.end(), Aabb::empty());
      std::fill(slot_count.begin(), slot_count.end(), 0);
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t s = static_cast<std::size_t>(slot(centres[ids[i]][a], a, centre_box, scale));
        slot_box[s].extend(boxes[ids[i]]);
        ++slot_count[s];
      }
      Aabb acc;
      std::size_t count = 0;
      for (int s = bins - 1; s > 0; --s) {
        acc.extend(slot_box[static_cast<std::size_t>(s)]);
        count += slot_count[static_cast<std::size_t>(s)];
        right_area[static_cast<std::size_t>(s)] = acc.surface_area();
        right_count[static_cast<std::size_t>(s)] = count;
      }
      acc = Aabb::empty();
      count = 0;
      for (int s = 0; s + 1 < bins; ++s) {
        acc.extend(slot_box[static_cast<std::size_t>(s)]);
        count += slot_count[static_cast<std::size_t>(s)];
        const std::size_t right = right_count[static_cast<std::size_t>(s + 1)];
        if (count == 0 || right == 0) continue;
        const double cost = static_cast<double>(acc.surface_area()) * static_cast<double>(count) +
                            right_area[static_cast<std::size_t>(s + 1)] * static_cast<double>(right);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_slot = s;
        }
      }
    }
    if (best_axis < 0) return begin;
    const int a = best_axis;
    const float scale = static_cast<float>(bins) / (centre_box.upper[a] - centre_box.lower[a]);
    const auto mid = std::stable_partition(ids.begin() + static_cast<std::ptrdiff_t>(begin),
                                           ids.begin() + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t id) {
                                             return slot(centres[id][a], a, centre_box, scale) <= best_slot;
                                           });
    const std::size_t m = static_cast<std::size_t>(mid - ids.begin());
    return m == end ? begin : m;
  }

  std::size_t median_split(std::vector<std::uint32_t>& ids, std::size_t begin, std::size_t end,
                           const Aabb& centre_box) {
    const Vec3 extent = centre_box.upper - centre_box.lower;
    const int a = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(ids.begin() + static_cast<std::ptrdiff_t>(begin), ids.begin() + static_cast<std::ptrdiff_t>(mid),
                     ids.begin() + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t x, std::uint32_t y) {
                       const float cx = centres[x][a], cy = centres[y][a];
                       return cx < cy || (cx == cy && x < y);
                     });
    return mid;
  }
};

Status bad_box(std::size_t i) {
  return make_error(ErrorCode::kInvalidData, "", "boxes[" + std::to_string(i) + "]", "",
                    "not finite: a BVH needs finite boxes (or Aabb::empty() to leave one out)");
}

}  // namespace

Status check_bvh_options(const BvhBuildOptions& options) {
  if (options.max_leaf_items < 1) {
    return invalid_argument("max_leaf_items", std::to_string(options.max_leaf_items), "must be at least 1");
  }
  if (options.bins < 2 || options.bins > 256) {
    return invalid_argument("bins", std::to_string(options.bins), "must be in [2, 256]");
  }
  return {};
}

Expected<BoxBvh> build_box_bvh(std::span<const Aabb> boxes, const BvhBuildOptions& options) {
  SINEW_RETURN_IF_ERROR(check_bvh_options(options));
  if (boxes.size() > (std::size_t{1} << 31)) {
    return make_error(ErrorCode::kLimitExceeded, "", "boxes", std::to_string(boxes.size()),
                      "a BVH indexes at most 2^31 boxes");
  }
  Builder b{boxes, std::vector<Vec3>(boxes.size()), options, {}};
  std::vector<std::uint32_t> ids;
  ids.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb& box = boxes[i];
    bool finite = true;
    for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(box.lower[a]) && std::isfinite(box.upper[a]);
    if (!finite) {
      if (box.lower == Aabb::empty().lower && box.upper == Aabb::empty().upper) continue;
      return bad_box(i);
    }
    if (box.is_empty()) continue;  // inverted: holds no point
    b.centres[i] = box.center();
    ids.push_back(static_cast<std::uint32_t>(i));
  }
  if (ids.empty()) return std::move(b.out);
  b.out.nodes.reserve(2 * (ids.size() / static_cast<std::size_t>(options.max_leaf_items) + 1));
  b.out.items.reserve(ids.size());
  b.out.nodes.emplace_back();
  b.build(0, ids, 0, ids.size(), 0);
  b.out.stats.node_count = static_cast<std::uint32_t>(b.out.nodes.size());
  b.out.stats.item_count = static_cast<std::uint32_t>(b.out.items.size());
  return std::move(b.out);
}

}  // namespace sinew::rt
