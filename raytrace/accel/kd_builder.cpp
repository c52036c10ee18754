// SAH kd-tree builder: Wald and Havran 2006, the O(N log N) event sweep.
//
// Every box contributes, per axis, a start and an end event (or one planar
// event when it has zero width on that axis). The events of each axis are
// sorted once at the root; a node sweeps them to find the cheapest split, then
// splits its lists into its children's lists in linear time, which keeps them
// sorted. A box that straddles the split is clipped to each child: for boxes
// (unlike triangles) clipping only moves that box's event on the split axis to
// the split position, so the two new events per straddler are sorted by item
// and merged in while the lists are written.
//
// Conventions the header leaves open:
// - No non-empty box: the tree has no nodes (an empty view).
// - A cell with zero surface area (a segment or a point) becomes a leaf: no
//   ray of positive measure hits it, so the SAH has nothing to weigh. The
//   stats' sah_cost of such a root is intersection_cost * N.
// - Splits lie strictly inside the cell, except a split exactly on a cell face
//   that cuts off the boxes lying flat in that face (planar side toward the
//   face). The empty bonus applies only when the empty child has positive
//   extent along the split axis.
// - Each axis's events are sorted by (position, type: end < planar < start,
//   item); among equal costs the lowest (position, axis, planar-below-first)
//   split wins. Leaf items are listed in increasing index order.
// - Areas are computed in double (a flat cell's area is its two faces); the
//   stats' sah_cost weighs every node by area(node) / area(root).
// - The depth is capped at kDepthCap whatever the options say.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "raytrace/accel/kd_tree.h"
#include "runtime/core/format_number.h"

namespace sinew::rt {
namespace {

constexpr int kDepthCap = 64;

// An event is one 64-bit key: order-preserving position bits above, the type
// (2 bits) and the item (30 bits) below, so integer order is the sort order
// (position, type, item) and merging is integer comparison.
using Event = std::uint64_t;
enum EventType : std::uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };
constexpr std::uint32_t kItemMask = (1u << 30) - 1;

std::uint32_t position_key(float position) {
  // +0.0f folds -0.0f into +0.0f so equal positions have equal keys.
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(position + 0.0f);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}
float key_position(std::uint32_t key) {
  const std::uint32_t bits = (key & 0x80000000u) ? (key & 0x7fffffffu) : ~key;
  return std::bit_cast<float>(bits);
}
Event make_event(float position, EventType type, std::uint32_t item) {
  return (static_cast<Event>(position_key(position)) << 32) | (static_cast<Event>(type) << 30) | item;
}
std::uint32_t event_pos_key(Event e) { return static_cast<std::uint32_t>(e >> 32); }
float event_position(Event e) { return key_position(event_pos_key(e)); }
EventType event_type(Event e) { return static_cast<EventType>((e >> 30) & 3u); }
std::uint32_t event_item(Event e) { return static_cast<std::uint32_t>(e) & kItemMask; }

// Where a node's events live in the builder's event stack: axis a's sorted
// events are [begin + offset(a), begin + offset(a) + count[a]).
struct EventRange {
  std::size_t begin = 0;
  std::size_t count[3] = {0, 0, 0};
  std::size_t offset(int axis) const {
    std::size_t o = 0;
    for (int a = 0; a < axis; ++a) o += count[a];
    return o;
  }
  std::size_t total() const { return count[0] + count[1] + count[2]; }
  std::size_t end() const { return begin + total(); }
};

struct Split {
  double cost = 0.0;
  int axis = -1;  // -1: no valid split
  float position = 0.0f;
  bool planar_below = true;
};

// Lower (cost, position, axis, planar side) wins, which makes the choice
// independent of the order candidates are visited in.
bool better(const Split& a, const Split& b) {
  if (b.axis < 0) return true;
  if (a.cost != b.cost) return a.cost < b.cost;
  if (a.position != b.position) return a.position < b.position;
  if (a.axis != b.axis) return a.axis < b.axis;
  return a.planar_below && !b.planar_below;
}

// In double from double extents: float cells near the float range would
// overflow to an infinite area (and a zero 1/area).
double surface_area(const Aabb& cell) {
  double e[3];
  for (int a = 0; a < 3; ++a) e[a] = static_cast<double>(cell.upper[a]) - static_cast<double>(cell.lower[a]);
  return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
}

enum Side : std::uint8_t { kBelow = 1, kAbove = 2, kBoth = 3 };

std::string format_box(const Aabb& b) {
  std::string s = "lower=(";
  for (int a = 0; a < 3; ++a) s += format_number(static_cast<double>(b.lower[a])) + (a < 2 ? ", " : ")");
  s += " upper=(";
  for (int a = 0; a < 3; ++a) s += format_number(static_cast<double>(b.upper[a])) + (a < 2 ? ", " : ")");
  return s;
}

Status validate_options(const KdBuildOptions& o) {
  if (!std::isfinite(o.traversal_cost) || o.traversal_cost < 0.0f)
    return invalid_argument("options.traversal_cost", format_number(static_cast<double>(o.traversal_cost)),
                            "must be finite and >= 0");
  if (!std::isfinite(o.intersection_cost) || o.intersection_cost < 0.0f)
    return invalid_argument("options.intersection_cost",
                            format_number(static_cast<double>(o.intersection_cost)), "must be finite and >= 0");
  if (!(o.empty_bonus >= 0.0f && o.empty_bonus < 1.0f))
    return invalid_argument("options.empty_bonus", format_number(static_cast<double>(o.empty_bonus)),
                            "must be in [0, 1)");
  if (o.max_leaf_items < 1)
    return invalid_argument("options.max_leaf_items", std::to_string(o.max_leaf_items), "must be >= 1");
  if (o.max_depth < 0)
    return invalid_argument("options.max_depth", std::to_string(o.max_depth), "must be >= 0 (0: automatic)");
  return {};
}

// NaN anywhere is an error; a box with lower > upper on some axis (which
// includes Aabb::empty() and its infinities) is skipped; any other infinity
// is an error.
Status validate_box(const Aabb& b, std::size_t index, bool* keep) {
  bool has_nan = false;
  bool finite = true;
  for (int a = 0; a < 3; ++a) {
    has_nan = has_nan || std::isnan(b.lower[a]) || std::isnan(b.upper[a]);
    finite = finite && std::isfinite(b.lower[a]) && std::isfinite(b.upper[a]);
  }
  *keep = false;
  if (!has_nan && b.is_empty()) return {};
  if (has_nan || !finite)
    return make_error(ErrorCode::kInvalidData, "", "boxes[" + std::to_string(index) + "]", format_box(b),
                      "box coordinates must be finite (an empty box has lower > upper)");
  *keep = true;
  return {};
}

class Builder {
 public:
  Builder(const KdBuildOptions& options, std::size_t box_count) : options_(options), side_(box_count, kBoth) {}

  Status build(std::span<const Aabb> boxes, const std::vector<std::uint32_t>& kept, KdTree* tree) {
    tree_ = tree;
    const std::uint32_t n = static_cast<std::uint32_t>(kept.size());
    Aabb bounds;
    for (std::uint32_t i : kept) bounds.extend(boxes[i]);
    tree->bounds = bounds;
    if (n == 0) return {};

    max_depth_ = options_.max_depth > 0
                     ? options_.max_depth
                     : static_cast<int>(std::lround(8.0 + 1.3 * std::log2(static_cast<double>(n))));
    max_depth_ = std::min(max_depth_, kDepthCap);
    root_area_ = surface_area(bounds);

    EventRange root = make_root_events(boxes, kept);
    return build_node(root, bounds, n, 0);
  }

 private:
  EventRange make_root_events(std::span<const Aabb> boxes, const std::vector<std::uint32_t>& kept) {
    EventRange range;
    for (int a = 0; a < 3; ++a) {
      for (std::uint32_t i : kept) {
        const float lo = boxes[i].lower[a];
        const float hi = boxes[i].upper[a];
        if (lo == hi) {
          events_.push_back(make_event(lo, kPlanar, i));
        } else {
          events_.push_back(make_event(lo, kStart, i));
          events_.push_back(make_event(hi, kEnd, i));
        }
      }
      range.count[a] = events_.size() - range.offset(a);
      radix_sort(events_.data() + range.offset(a), range.count[a]);
    }
    return range;
  }

  // The one sort of the build: LSD radix sort of the 64-bit keys, 11 bits a
  // pass, skipping passes in which every key has the same digit.
  void radix_sort(Event* keys, std::size_t count) {
    if (count < 256) {
      std::sort(keys, keys + count);
      return;
    }
    constexpr int kBits = 11;
    constexpr std::size_t kBuckets = std::size_t{1} << kBits;
    sort_scratch_.resize(count);
    Event* from = keys;
    Event* to = sort_scratch_.data();
    std::vector<std::size_t> histogram(kBuckets);
    for (int shift = 0; shift < 64; shift += kBits) {
      std::fill(histogram.begin(), histogram.end(), 0);
      for (std::size_t i = 0; i < count; ++i) ++histogram[(from[i] >> shift) & (kBuckets - 1)];
      if (histogram[(from[0] >> shift) & (kBuckets - 1)] == count) continue;
      std::size_t sum = 0;
      for (std::size_t& h : histogram) sum += std::exchange(h, sum);
      for (std::size_t i = 0; i < count; ++i) to[histogram[(from[i] >> shift) & (kBuckets - 1)]++] = from[i];
      std::swap(from, to);
    }
    if (from != keys) std::copy(from, from + count, keys);
  }

  // The children's areas are linear in the split position: with u, v the
  // cell's other two extents, area(t) = 2uv + 2(u + v) t for a child of width
  // t along the axis.
  struct AxisSweep {
    double lo, hi;
    double face_area;  // 2uv
    double perimeter;  // 2(u + v)
    double inv_area;
  };

  void consider(const AxisSweep& g, int axis, float p, std::uint32_t nl, std::uint32_t np, std::uint32_t nr,
                Split* best) const {
    const double x = static_cast<double>(p);
    if (x < g.lo || x > g.hi) return;  // cannot happen with clipped events; be safe
    const bool inside = x > g.lo && x < g.hi;
    const double below_area = g.face_area + g.perimeter * (x - g.lo);
    const double above_area = g.face_area + g.perimeter * (g.hi - x);
    auto cost = [&](std::uint32_t n_below, std::uint32_t n_above) {
      // The empty bonus only pays for cutting off empty space with volume.
      const bool empty_with_volume = (n_below == 0 && x > g.lo) || (n_above == 0 && x < g.hi);
      const double bonus = empty_with_volume ? 1.0 - static_cast<double>(options_.empty_bonus) : 1.0;
      return static_cast<double>(options_.traversal_cost) +
             static_cast<double>(options_.intersection_cost) * bonus *
                 (below_area * n_below + above_area * n_above) * g.inv_area;
    };
    // Planar boxes below: allowed inside, or on the lower face when there are
    // planar boxes to cut off; symmetrically above. Without planar boxes both
    // sides are the same candidate (and "below" wins the tie).
    if (inside || (x == g.lo && np > 0)) offer({cost(nl + np, nr), axis, p, true}, best);
    if ((inside && np > 0) || (x == g.hi && np > 0)) offer({cost(nl, nr + np), axis, p, false}, best);
  }

  static void offer(const Split& s, Split* best) {
    if (best->axis >= 0 && s.cost > best->cost) return;  // the common case, decided cheaply
    if (better(s, *best)) *best = s;
  }

  // The sweep of Wald and Havran: per axis, walk the sorted events one
  // position at a time, keeping the counts of boxes entirely below, lying in
  // the plane and entirely above.
  Split find_split(const EventRange& range, const Aabb& cell, std::uint32_t n) const {
    Split best;
    const double inv_area = 1.0 / surface_area(cell);
    auto extent = [&](int a) { return static_cast<double>(cell.upper[a]) - static_cast<double>(cell.lower[a]); };
    for (int axis = 0; axis < 3; ++axis) {
      if (!(cell.upper[axis] > cell.lower[axis])) continue;  // never split a flat axis
      const double u = extent((axis + 1) % 3);
      const double v = extent((axis + 2) % 3);
      const AxisSweep g{static_cast<double>(cell.lower[axis]), static_cast<double>(cell.upper[axis]), 2.0 * u * v,
                        2.0 * (u + v), inv_area};
      const Event* ev = events_.data() + range.begin + range.offset(axis);
      const std::size_t count = range.count[axis];
      std::uint32_t nl = 0;
      std::uint32_t nr = n;
      // Counts of the events at the current position, by type; counted
      // without branching on the type, which is unpredictable.
      std::uint32_t at[3] = {0, 0, 0};
      std::uint32_t key = count ? event_pos_key(ev[0]) : 0;
      auto close_position = [&] {
        nr -= at[kPlanar] + at[kEnd];
        consider(g, axis, key_position(key), nl, at[kPlanar], nr, &best);
        nl += at[kStart] + at[kPlanar];
        at[0] = at[1] = at[2] = 0;
      };
      for (std::size_t i = 0; i < count; ++i) {
        if (event_pos_key(ev[i]) != key) {
          close_position();
          key = event_pos_key(ev[i]);
        }
        ++at[event_type(ev[i])];
      }
      if (count) close_position();
    }
    return best;
  }

  // Marks every item of the node below, above or both for `split`, and
  // collects the straddlers (sorted by item).
  void classify(const EventRange& range, const Split& split) {
    const Event* e = events_.data() + range.begin + range.offset(split.axis);
    const float p = split.position;
    straddlers_.clear();
    // Start precedes end for the same item (start < end), so one pass sees a
    // box's start before deciding at its end.
    for (std::size_t i = 0; i < range.count[split.axis]; ++i) {
      const std::uint32_t item = event_item(e[i]);
      const float pos = event_position(e[i]);
      switch (event_type(e[i])) {
        case kStart:
          side_[item] = pos >= p ? kAbove : kBoth;
          break;
        case kEnd:
          if (pos <= p) {
            side_[item] = kBelow;
          } else if (side_[item] == kBoth) {
            straddlers_.push_back(item);
          }
          break;
        case kPlanar:
          side_[item] = pos < p ? kBelow : pos > p ? kAbove : split.planar_below ? kBelow : kAbove;
          break;
      }
    }
    std::sort(straddlers_.begin(), straddlers_.end());
  }

  // Writes one axis's events of the node into the children's lists. On the
  // split axis, straddlers end at the split below and start there above;
  // those new events are merged in by key.
  void distribute_axis(const Event* in, std::size_t count, bool split_axis, float p, Event* below,
                       std::size_t* n_below, Event* above, std::size_t* n_above) const {
    std::size_t nb = 0, na = 0, jb = 0, ja = 0;
    const std::size_t s = straddlers_.size();
    auto new_below = [&](std::size_t j) { return make_event(p, kEnd, straddlers_[j]); };
    auto new_above = [&](std::size_t j) { return make_event(p, kStart, straddlers_[j]); };
    auto emit_below = [&](Event ev) {
      while (jb < s && new_below(jb) < ev) below[nb++] = new_below(jb++);
      below[nb++] = ev;
    };
    auto emit_above = [&](Event ev) {
      while (ja < s && new_above(ja) < ev) above[na++] = new_above(ja++);
      above[na++] = ev;
    };
    if (!split_axis) {
      // Off the split axis an event goes where its box goes; written to both
      // outputs and kept by advancing each cursor or not, without branches.
      for (std::size_t i = 0; i < count; ++i) {
        const Event ev = in[i];
        const std::uint8_t side = side_[event_item(ev)];
        below[nb] = ev;
        above[na] = ev;
        nb += side & kBelow;
        na += (side & kAbove) >> 1;
      }
      *n_below = nb;
      *n_above = na;
      return;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const Event ev = in[i];
      const std::uint8_t side = side_[event_item(ev)];
      if (side == kBelow) {
        emit_below(ev);
      } else if (side == kAbove) {
        emit_above(ev);
      } else if (event_type(ev) == kStart) {
        emit_below(ev);
      } else {
        emit_above(ev);
      }
    }
    while (jb < s) below[nb++] = new_below(jb++);
    while (ja < s) above[na++] = new_above(ja++);
    *n_below = nb;
    *n_above = na;
  }

  // Splits the node's events into the children's, leaving the above child's
  // list at the node's begin and the below child's right after it (the below
  // child is built first, on top of the stack).
  void split_events(const EventRange& range, const Split& split, EventRange* below, EventRange* above) {
    const std::size_t bound = range.total() + straddlers_.size();
    const std::size_t top = range.end();
    // +1: the branchless writes may store one element past a list's end.
    const std::size_t need = top + 2 * bound + 1;
    if (events_.size() < need) events_.resize(std::max(need, events_.size() * 2));
    std::size_t above_at = top;
    std::size_t below_at = top + bound;
    for (int a = 0; a < 3; ++a) {
      distribute_axis(events_.data() + range.begin + range.offset(a), range.count[a], a == split.axis,
                      split.position, events_.data() + below_at, &below->count[a], events_.data() + above_at,
                      &above->count[a]);
      below_at += below->count[a];
      above_at += above->count[a];
    }
    // Compact: both moves go to lower addresses and do not overlap each other.
    const auto base = events_.begin();
    std::copy(base + static_cast<std::ptrdiff_t>(top), base + static_cast<std::ptrdiff_t>(top + above->total()),
              base + static_cast<std::ptrdiff_t>(range.begin));
    above->begin = range.begin;
    const std::size_t below_src = top + bound;
    std::copy(base + static_cast<std::ptrdiff_t>(below_src),
              base + static_cast<std::ptrdiff_t>(below_src + below->total()),
              base + static_cast<std::ptrdiff_t>(above->end()));
    below->begin = above->end();
  }

  Status emit_leaf(std::size_t node, const EventRange& range, std::uint32_t n, const Aabb& cell) {
    if (tree_->items.size() + n > KdNode::kMaxIndex)
      return make_error(ErrorCode::kLimitExceeded, "", "items", std::to_string(tree_->items.size() + n),
                        "more kd-tree item references than a node can index");
    const std::size_t first = tree_->items.size();
    // Each item has exactly one start or planar event on axis 0.
    const Event* e = events_.data() + range.begin;
    for (std::size_t i = 0; i < range.count[0]; ++i)
      if (event_type(e[i]) != kEnd) tree_->items.push_back(event_item(e[i]));
    std::sort(tree_->items.begin() + static_cast<std::ptrdiff_t>(first), tree_->items.end());
    tree_->nodes[node] = KdNode::leaf(n ? static_cast<std::uint32_t>(first) : 0u, n);
    KdTreeStats& st = tree_->stats;
    ++st.leaf_count;
    if (n == 0) ++st.empty_leaf_count;
    st.item_refs += n;
    st.sah_cost += static_cast<double>(options_.intersection_cost) * n * area_ratio(cell);
    return {};
  }

  double area_ratio(const Aabb& cell) const { return root_area_ > 0.0 ? surface_area(cell) / root_area_ : 1.0; }

  Status build_node(const EventRange& range, const Aabb& cell, std::uint32_t n, int depth) {
    if (tree_->nodes.size() >= KdNode::kMaxIndex)
      return make_error(ErrorCode::kLimitExceeded, "", "nodes", std::to_string(tree_->nodes.size() + 1),
                        "more kd-tree nodes than an index can address");
    const std::size_t node = tree_->nodes.size();
    tree_->nodes.emplace_back();
    tree_->stats.max_depth = std::max(tree_->stats.max_depth, depth);

    Split split;
    const bool may_split = n > static_cast<std::uint32_t>(options_.max_leaf_items) && depth < max_depth_ &&
                           surface_area(cell) > 0.0;
    if (may_split) split = find_split(range, cell, n);
    const double leaf_cost = static_cast<double>(options_.intersection_cost) * n;
    if (split.axis < 0 || !(split.cost < leaf_cost)) return emit_leaf(node, range, n, cell);

    classify(range, split);
    EventRange below, above;
    split_events(range, split, &below, &above);
    tree_->stats.sah_cost += static_cast<double>(options_.traversal_cost) * area_ratio(cell);

    Aabb below_cell = cell;
    Aabb above_cell = cell;
    below_cell.upper[split.axis] = split.position;
    above_cell.lower[split.axis] = split.position;
    // Item counts: each item has one start or planar event per axis.
    auto items_in = [&](const EventRange& r) {
      std::uint32_t c = 0;
      const Event* e = events_.data() + r.begin;
      for (std::size_t i = 0; i < r.count[0]; ++i) c += event_type(e[i]) != kEnd;
      return c;
    };
    const std::uint32_t n_below = items_in(below);
    const std::uint32_t n_above = items_in(above);
    SINEW_RETURN_IF_ERROR(build_node(below, below_cell, n_below, depth + 1));
    const std::size_t above_index = tree_->nodes.size();
    tree_->nodes[node] = KdNode::inner(split.axis, split.position, static_cast<std::uint32_t>(above_index));
    return build_node(above, above_cell, n_above, depth + 1);
  }

  const KdBuildOptions& options_;
  std::vector<std::uint8_t> side_;          // per input box, valid for the node being split
  std::vector<std::uint32_t> straddlers_;   // reused by every split
  std::vector<Event> events_;               // stack of pending nodes' event lists
  std::vector<Event> sort_scratch_;
  KdTree* tree_ = nullptr;
  int max_depth_ = 0;
  double root_area_ = 0.0;
};

}  // namespace

Expected<KdTree> build_kd_tree(std::span<const Aabb> boxes, const KdBuildOptions& options) {
  SINEW_RETURN_IF_ERROR(validate_options(options));
  if (boxes.size() > KdNode::kMaxIndex)
    return make_error(ErrorCode::kLimitExceeded, "", "boxes.size()", std::to_string(boxes.size()),
                      "a kd-tree indexes at most 2^30 - 1 boxes");
  std::vector<std::uint32_t> kept;
  kept.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    bool keep = false;
    SINEW_RETURN_IF_ERROR(validate_box(boxes[i], i, &keep));
    if (keep) kept.push_back(static_cast<std::uint32_t>(i));
  }
  KdTree tree;
  Builder builder(options, boxes.size());
  SINEW_RETURN_IF_ERROR(builder.build(boxes, kept, &tree));
  tree.stats.node_count = static_cast<std::uint32_t>(tree.nodes.size());
  return tree;
}

}  // namespace sinew::rt
