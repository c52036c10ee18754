#include "raytrace/cull/ray_bound.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "raytrace/cull/interval_bound.h"
#include "raytrace/cull/interval_walk.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/math/float4.h"
#include "runtime/math/float8.h"

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

namespace {

// Lanes not in `lanes` repeat an active lane's values, so they widen nothing.
Float8 pick(const float* p, Mask8 use, int first) { return select(use, Float8::load(p), Float8(p[first])); }

void fold_in(bool empty, float* lo, float* hi, Float8 x) {
  if (empty) {
    x.store(lo);
    x.store(hi);
  } else {
    min(Float8::load(lo), x).store(lo);
    max(Float8::load(hi), x).store(hi);
  }
}

}  // namespace

void RayBound::fold_points(int a, Float8 lo, Float8 hi) {
  // Folded before the directions, which clear empty_.
  if (empty_) {
    lo.store(lanes_.p_min[a]);
    hi.store(lanes_.p_max[a]);
  } else {
    min(Float8::load(lanes_.p_min[a]), lo).store(lanes_.p_min[a]);
    max(Float8::load(lanes_.p_max[a]), hi).store(lanes_.p_max[a]);
  }
}

bool RayBound::add_directions(const float* const d[3], std::uint32_t lanes) {
  const Mask8 use = Mask8::from_bits(lanes);
  const int first = std::countr_zero(lanes);
  Mask8 finite = Mask8::from_bits(0xFFu);
  for (int a = 0; a < 3; ++a) {
    const Float8 da = pick(d[a], use, first);
    finite = finite & is_finite(da);
    fold_in(empty_, lanes_.d_min[a], lanes_.d_max[a], da);
  }
  empty_ = false;
  folded_ = false;
  return finite.bits() == 0xFFu;
}

void RayBound::add_lanes(const float* const o[3], const float* const d[3], const float* t_min, const float* t_max,
                         std::uint32_t lanes) {
  lanes &= 0xFFu;
  if (lanes == 0) return;
  const Mask8 use = Mask8::from_bits(lanes);
  const int first = std::countr_zero(lanes);
  const Float8 t0p = pick(t_min, use, first), t1p = pick(t_max, use, first);
  Mask8 finite = is_finite(t0p) & (t0p < t1p);
  // A ray's points lie between its two ends (an infinite one bounds none).
  const Mask8 bounded = is_finite(t1p);
  for (int a = 0; a < 3; ++a) {
    const Float8 oa = pick(o[a], use, first), da = pick(d[a], use, first);
    finite = finite & is_finite(oa);
    fold_in(lane_origins_empty_, lanes_.o_min[a], lanes_.o_max[a], oa);
    const Float8 start = oa + t0p * da, end = oa + t1p * da;
    fold_points(a, select(bounded, min(start, end), Float8(-kInf)), select(bounded, max(start, end), Float8(kInf)));
  }
  if (lane_origins_empty_) {
    t0p.store(lanes_.t_min);
    t1p.store(lanes_.t_max);
  } else {
    min(Float8::load(lanes_.t_min), t0p).store(lanes_.t_min);
    max(Float8::load(lanes_.t_max), t1p).store(lanes_.t_max);
  }
  lane_origins_empty_ = false;
  if (!add_directions(d, lanes) || finite.bits() != 0xFFu) unbounded_ = true;
}

bool RayBound::add_shared(const Vec3& origin, float t_min, float t_max) {
  bool finite = std::isfinite(t_min) && t_min < t_max;
  for (int a = 0; a < 3; ++a) {
    finite = finite && std::isfinite(origin[a]);
    shared_o_lo_[a] = shared_empty_ ? origin[a] : std::min(shared_o_lo_[a], origin[a]);
    shared_o_hi_[a] = shared_empty_ ? origin[a] : std::max(shared_o_hi_[a], origin[a]);
  }
  shared_t_lo_ = shared_empty_ ? t_min : std::min(shared_t_lo_, t_min);
  shared_t_hi_ = shared_empty_ ? t_max : std::max(shared_t_hi_, t_max);
  shared_empty_ = false;
  return finite;
}

template <class LanesOf>
void RayBound::add_shared_groups(const Vec3& origin, const float* const d[3], float t_min, float t_max,
                                 std::size_t groups, LanesOf&& lanes_of) {
  // The running extremes stay in registers; lanes never in use keep +-inf,
  // which no fold picks.
  const Float8 plus(kInf), minus(-kInf);
  Float8 lo[3] = {plus, plus, plus}, hi[3] = {minus, minus, minus};
  // The rays' points (with an infinite t_max: none bounded) over [t_min, t_max].
  const bool bounded = std::isfinite(t_max);
  Float8 p_lo[3] = {plus, plus, plus}, p_hi[3] = {minus, minus, minus};
  Mask8 finite = Mask8::from_bits(0xFFu);
  std::uint32_t any = 0;
  for (std::size_t k = 0; k < groups; ++k) {
    const std::uint32_t lanes = lanes_of(k) & 0xFFu;
    if (lanes == 0) continue;
    any |= lanes;
    const Mask8 use = Mask8::from_bits(lanes);
    for (int a = 0; a < 3; ++a) {
      const Float8 x = Float8::load(d[a] + 8 * k);
      finite = finite & (is_finite(x) | !use);
      lo[a] = min(lo[a], select(use, x, plus));
      hi[a] = max(hi[a], select(use, x, minus));
      if (bounded) {
        const Float8 start = Float8(origin[a]) + Float8(t_min) * x, end = Float8(origin[a]) + Float8(t_max) * x;
        p_lo[a] = min(p_lo[a], select(use, min(start, end), plus));
        p_hi[a] = max(p_hi[a], select(use, max(start, end), minus));
      }
    }
  }
  if (any == 0) return;
  for (int a = 0; a < 3; ++a) {
    fold_points(a, bounded ? p_lo[a] : minus, bounded ? p_hi[a] : plus);
    if (empty_) {
      lo[a].store(lanes_.d_min[a]);
      hi[a].store(lanes_.d_max[a]);
    } else {
      min(Float8::load(lanes_.d_min[a]), lo[a]).store(lanes_.d_min[a]);
      max(Float8::load(lanes_.d_max[a]), hi[a]).store(lanes_.d_max[a]);
    }
  }
  empty_ = false;
  folded_ = false;
  if (!add_shared(origin, t_min, t_max) || finite.bits() != 0xFFu) unbounded_ = true;
}

void RayBound::add_lanes(const Vec3& origin, const float* const d[3], float t_min, float t_max,
                         std::uint32_t lanes) {
  add_shared_groups(origin, d, t_min, t_max, 1, [&](std::size_t) { return lanes; });
}

void RayBound::add_groups(const Vec3& origin, const float* const d[3], float t_min, float t_max,
                          std::span<const std::uint8_t> lanes) {
  add_shared_groups(origin, d, t_min, t_max, lanes.size(), [&](std::size_t k) { return std::uint32_t{lanes[k]}; });
}

void RayBound::add_run(const Vec3& origin, const float* const d[3], float t_min, float t_max, std::size_t rays) {
  add_shared_groups(origin, d, t_min, t_max, (rays + 7) / 8, [&](std::size_t k) {
    const std::size_t left = rays - 8 * k;
    return left >= 8 ? 0xFFu : (1u << left) - 1u;
  });
}

void RayBound::fold() const {
  if (folded_ || empty_) return;
  o_mag_ = d_mag_ = 0.0f;
  const float big = std::numeric_limits<float>::max();
  for (int a = 0; a < 3; ++a) {
    o_lo_[a] = shared_empty_ ? big : shared_o_lo_[a];
    o_hi_[a] = shared_empty_ ? -big : shared_o_hi_[a];
    if (!lane_origins_empty_) {
      o_lo_[a] = std::min(o_lo_[a], reduce_min(Float8::load(lanes_.o_min[a])));
      o_hi_[a] = std::max(o_hi_[a], reduce_max(Float8::load(lanes_.o_max[a])));
    }
    p_lo_[a] = reduce_min(Float8::load(lanes_.p_min[a]));
    p_hi_[a] = reduce_max(Float8::load(lanes_.p_max[a]));
    d_lo_[a] = reduce_min(Float8::load(lanes_.d_min[a]));
    d_hi_[a] = reduce_max(Float8::load(lanes_.d_max[a]));
    o_mag_ = std::max({o_mag_, std::fabs(o_lo_[a]), std::fabs(o_hi_[a])});
    d_mag_ = std::max({d_mag_, std::fabs(d_lo_[a]), std::fabs(d_hi_[a])});
  }
  t_lo_ = shared_empty_ ? kInf : shared_t_lo_;
  t_hi_ = shared_empty_ ? -kInf : shared_t_hi_;
  if (!lane_origins_empty_) {
    t_lo_ = std::min(t_lo_, reduce_min(Float8::load(lanes_.t_min)));
    t_hi_ = std::max(t_hi_, reduce_max(Float8::load(lanes_.t_max)));
  }
  folded_ = true;
}

float RayBound::world_slack_bound(float scene_magnitude) const {
  fold();
  return traversal_slack_bound(o_mag_, d_mag_, t_hi_, scene_magnitude);
}

IntervalBound RayBound::test() const {
  fold();
  RayRanges r;
  for (int a = 0; a < 3; ++a) {
    r.o_lo[a] = o_lo_[a];
    r.o_hi[a] = o_hi_[a];
    r.d_lo[a] = d_lo_[a];
    r.d_hi[a] = d_hi_[a];
  }
  r.t_lo = t_lo_;
  r.t_hi = t_hi_;
  for (int a = 0; a < 3; ++a) {
    r.p_lo[a] = p_lo_[a];
    r.p_hi[a] = p_hi_[a];
  }
  r.finite = !unbounded_;
  return IntervalBound(r);
}

void cull_objects(const Scene& scene, const RayBound& bound, std::vector<std::uint32_t>& out, float extra_grow,
                  std::uint32_t ray_mask) {
  const TopLevel& top = scene.top_level();
  const KdTreeView tree = top.view();
  if (tree.empty() || bound.empty()) return;
  const std::span<const TopLevelObject> objects = top.objects();
  const IntervalBound test = bound.test();
  // One grow for every box and cell: the largest slack of any box in the
  // scene. A point within an object's slack of the object lies within that
  // much of a cell that lists the object.
  const float grow = bound.world_slack_bound(detail::max_abs(tree.bounds)) + extra_grow;
  const std::span<const ObjectRun> runs = top.runs();
  if (runs.size() <= kFlatCullObjects) {
    // A few dozen runs (characters, grounds): one box test each, and one
    // per member of the runs a ray may enter, costs less than walking the
    // tree's cells to them (most tiles miss a character's box, which skips
    // its bones at once). A run's box holds its members' and its margin is
    // no smaller (the margin grows with the coordinates), so a member a ray
    // may enter never sits in a run it cannot. In index order, as the
    // walk's sorted output.
    for (const ObjectRun& run : runs) {
      if (run.count > 1 && !test.may_enter(run.box, grow)) continue;
      for (std::uint32_t object = run.first; object < run.first + run.count; ++object) {
        if ((objects[object].mask & ray_mask) != 0 && test.may_enter(objects[object].box, grow)) out.push_back(object);
      }
    }
    return;
  }
  // Walk the top-level tree over the cells the set may enter; each object
  // is tested once (objects straddle splits and sit in several leaves).
  thread_local std::vector<std::uint32_t> stamp;
  thread_local std::uint32_t stamp_value = 0;
  if (stamp.size() < objects.size()) stamp.assign(objects.size(), 0);
  if (++stamp_value == 0) {
    std::fill(stamp.begin(), stamp.end(), 0);
    stamp_value = 1;
  }
  const std::size_t first_out = out.size();
  for_each_reached_leaf(tree, test, grow, [&](std::span<const std::uint32_t> items) {
    for (const std::uint32_t object : items) {
      if (stamp[object] == stamp_value) continue;
      stamp[object] = stamp_value;
      if ((objects[object].mask & ray_mask) != 0 && test.may_enter(objects[object].box, grow)) out.push_back(object);
    }
    return true;
  });
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first_out), out.end());
}

}  // namespace sinew::rt
