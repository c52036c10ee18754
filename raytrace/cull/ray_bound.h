// RayBound: the ranges of a whole set of rays (a tile's primary rays, its
// shadow rays), gathered eight lanes at a time and handed on as an
// IntervalBound; and cull_objects, the top-level objects some ray of the set
// may enter. Every box grows by a bound on the traversal's own slack
// (traversal_slack_bound), so culling changes no result. docs/RAYTRACE.md,
// "RayBound and interval bounds".
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/cull/interval_bound.h"
#include "raytrace/scene/scene.h"
#include "runtime/math/aabb.h"
#include "runtime/math/float8.h"
#include "runtime/math/types.h"

namespace sinew::rt {

// An upper bound on the slack the traversal grows a world-space box by
// (kFrameRelativeSlack * (|o| + t_end |d| + |box|), traverse/traversal.h)
// over rays whose origin and direction coordinates are at most o_mag and
// d_mag in magnitude and whose t_max is at most t_hi, for boxes inside a
// scene of magnitude scene_magnitude. The reach t_end |d| is at most
// t_hi d_mag when t_hi is finite (t_end never passes t_max); otherwise it is
// a finite hit's, inside the scene, so at most o_mag + scene_magnitude.
// Shadow rays (t_hi = 1) reach only their own length, not the scene's.
inline float traversal_slack_bound(float o_mag, float d_mag, float t_hi, float scene_magnitude) {
  const float reach = std::isfinite(t_hi) ? 1.01f * t_hi * d_mag : 1.01f * (o_mag + scene_magnitude);
  return kFrameRelativeSlack * 1.01f * (o_mag + reach + scene_magnitude);
}

class RayBound {
 public:
  // Adds the rays of `lanes` (bit i: lane i) of an eight-lane SoA packet.
  // Accumulates lane by lane; the eight lanes are folded into one range
  // only when the bound is used.
  void add_lanes(const float* const o[3], const float* const d[3], const float* t_min, const float* t_max,
                 std::uint32_t lanes);
  // Adds eight rays from one shared origin with one [t_min, t_max]: only
  // the directions are folded lane by lane (a tile's camera rays, a point
  // light's shadow rays).
  void add_lanes(const Vec3& origin, const float* const d[3], float t_min, float t_max, std::uint32_t lanes);
  // The same for consecutive groups of eight at d[axis][8 k + lane]: group
  // k's lanes lanes[k] (a tile's camera rays, block by block), or every ray
  // of a run of `rays` (a point light's shadow rays). The same bound as
  // adding each group on its own, at a fraction of the cost.
  void add_groups(const Vec3& origin, const float* const d[3], float t_min, float t_max,
                  std::span<const std::uint8_t> lanes);
  void add_run(const Vec3& origin, const float* const d[3], float t_min, float t_max, std::size_t rays);

  bool empty() const { return empty_; }

  // An upper bound, over every ray of the set, on the slack the traversal
  // grows a world-space box by when it clips a ray against it, for boxes
  // inside a scene of magnitude `scene_magnitude` (traverse/traversal.h).
  float world_slack_bound(float scene_magnitude) const;

  // The bound as a box test (IntervalBound::may_enter) and walk
  // (cull/interval_walk.h), computed once per set.
  IntervalBound test() const;

 private:
  // Folds the directions of `lanes` (not 0) of rays with their own origins
  // in; false when one is not finite.
  bool add_directions(const float* const d[3], std::uint32_t lanes);
  // Folds in one shared origin and parameter range; false when not finite.
  bool add_shared(const Vec3& origin, float t_min, float t_max);
  // add_groups for `groups` groups, group k's lanes lanes_of(k).
  template <class LanesOf>
  void add_shared_groups(const Vec3& origin, const float* const d[3], float t_min, float t_max, std::size_t groups,
                         LanesOf&& lanes_of);
  void fold() const;
  // Folds lanes' lowest and highest points on axis a into p_min, p_max.
  void fold_points(int a, Float8 lo, Float8 hi);

  // Per lane, the running minimum and maximum of each quantity: the
  // directions of every ray added, the origins and parameters of the rays
  // added with their own (lane_origins_empty_ says whether any were).
  // p_min, p_max: the points o + t d at t_min and t_max of every ray
  // (RayRanges::p_lo, p_hi; +-inf for an infinite t).
  struct Lanes {
    float o_min[3][8], o_max[3][8], d_min[3][8], d_max[3][8];
    float p_min[3][8], p_max[3][8];
    float t_min[8], t_max[8];
  };
  Lanes lanes_{};
  // The shared origins and parameter ranges of the rays added with one.
  float shared_o_lo_[3] = {0, 0, 0}, shared_o_hi_[3] = {0, 0, 0};
  float shared_t_lo_ = 0.0f, shared_t_hi_ = 0.0f;
  bool empty_ = true;               // no ray at all (so no direction)
  bool lane_origins_empty_ = true;  // no ray with its own origin
  bool shared_empty_ = true;        // no ray with a shared origin
  bool unbounded_ = false;  // a non-finite ray was added
  // Folded (by fold(), on first use).
  mutable bool folded_ = false;
  mutable float o_lo_[3] = {0, 0, 0}, o_hi_[3] = {0, 0, 0};
  mutable float d_lo_[3] = {0, 0, 0}, d_hi_[3] = {0, 0, 0};
  mutable float t_lo_ = 0.0f, t_hi_ = 0.0f;
  mutable float p_lo_[3] = {0, 0, 0}, p_hi_[3] = {0, 0, 0};
  mutable float o_mag_ = 0.0f, d_mag_ = 0.0f;
};

// Scenes with at most this many runs of top-level objects (characters,
// static meshes: accel/top_level.h ObjectRun) are culled by testing each
// run's box, then the boxes of the runs entered; larger ones by walking the
// top-level tree.
inline constexpr std::size_t kFlatCullObjects = 64;

// The top-level objects (indices into scene.top_level().objects(), in
// ascending order) that some ray of `bound` may enter, every box grown by
// extra_grow beyond the bound's own slack bound, leaving out those whose
// mask shares no bit with `ray_mask` (accel/top_level.h). Appends to `out`.
void cull_objects(const Scene& scene, const RayBound& bound, std::vector<std::uint32_t>& out,
                  float extra_grow = 0.0f, std::uint32_t ray_mask = kAllMaskBits);

}  // namespace sinew::rt
