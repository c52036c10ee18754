// IntervalBound (cull/interval_bound.h), the box test a large packet pays
// per kd-tree cell, built as traverse/large_packet.cpp builds it (groups of
// eight rays into a RangeAccumulator, reduced once, boxes grown by
// grow_for): entry() never returns +inf for a box some ray of the set
// enters and is never later than that ray's entry parameter (both against a
// double-precision slab test), with and without a parameter limit; it gives
// +inf for boxes behind every origin and beyond every ray's reach, and the
// hand-computed entry of an axis-aligned set. Also the ranges themselves
// (only the lanes in each group's mask, non-finite rays bound nothing),
// crossing_lo / crossing_hi and slab_passage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "raytrace/cull/interval_bound.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/traverse/ray_frames.h"
#include "runtime/math/aabb.h"
#include "runtime/math/float4.h"
#include "runtime/math/float8.h"
#include "runtime/math/types.h"
#include "tests/support/slab_test.h"

namespace sinew {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kNoEntry = std::numeric_limits<double>::infinity();

float unit(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1.0p-24f; }
float signed_unit(std::mt19937& g) { return 2.0f * unit(g) - 1.0f; }
Vec3 random_vec(std::mt19937& g) { return Vec3(signed_unit(g), signed_unit(g), signed_unit(g)); }
float max_abs(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }
float max_abs(const Aabb& box) { return std::max(max_abs(box.lower), max_abs(box.upper)); }

// The parameter at which the ray o + t d, t in [t0, t1], enters `box` (the
// double-precision slab test of tests/support/slab_test.h); +inf where it
// does not enter.
double entry_parameter(const Vec3& o, const Vec3& d, double t0, double t1, const Aabb& box) {
  const auto [enter, leave] = testing_support::ray_box_passage(o, d, t0, t1, box);
  return enter <= leave ? enter : kNoEntry;
}

// A set of rays as a large packet holds them: groups of eight lanes,
// structure of arrays, a lane mask per group.
struct RaySet {
  explicit RaySet(int group_count)
      : groups(group_count), n(8 * static_cast<std::size_t>(group_count)), t0(n, 0.0f), t1(n, kInf),
        lanes(static_cast<std::size_t>(group_count), 0xFFu) {
    for (int a = 0; a < 3; ++a) {
      o[a].assign(n, 0.0f);
      d[a].assign(n, 0.0f);
    }
  }
  void put(std::size_t k, const Vec3& from, const Vec3& along, float t_min, float t_max) {
    for (int a = 0; a < 3; ++a) {
      o[a][k] = from[a];
      d[a][k] = along[a];
    }
    t0[k] = t_min;
    t1[k] = t_max;
  }
  bool on(std::size_t k) const { return k / 8 < lanes.size() && (lanes[k / 8] >> (k % 8) & 1u) != 0; }
  Vec3 origin_of(std::size_t k) const { return Vec3(o[0][k], o[1][k], o[2][k]); }
  Vec3 direction_of(std::size_t k) const { return Vec3(d[0][k], d[1][k], d[2][k]); }
  std::vector<std::size_t> active() const {
    std::vector<std::size_t> out;
    for (std::size_t k = 0; k < n; ++k) {
      if (on(k)) out.push_back(k);
    }
    return out;
  }
  // Every group's lanes added as large_packet.cpp adds them.
  void add_to(rt::RangeAccumulator& acc) const {
    for (int gr = 0; gr < groups; ++gr) {
      const std::size_t k0 = 8 * static_cast<std::size_t>(gr);
      const Vec3x8 ox{Float8::load(&o[0][k0]), Float8::load(&o[1][k0]), Float8::load(&o[2][k0])};
      const Vec3x8 dx{Float8::load(&d[0][k0]), Float8::load(&d[1][k0]), Float8::load(&d[2][k0])};
      acc.add(ox, dx, Float8::load(&t0[k0]), Float8::load(&t1[k0]), lanes[static_cast<std::size_t>(gr)]);
    }
  }
  rt::RayRanges ranges() const {
    rt::RangeAccumulator acc;
    add_to(acc);
    return acc.ranges();
  }
  int groups;
  std::size_t n;
  std::vector<float> o[3], d[3], t0, t1;
  std::vector<std::uint8_t> lanes;
};

// Conservative: sets of one to eight groups (8 to 64 rays, sometimes with
// random lane masks) from one shared origin or scattered origins, their
// directions of one sign per axis or of both, exactly zero or too small to
// bound on an axis, of magnitudes from 1e-20 to 1e20 (per set or per lane),
// with finite and infinite t ranges, at scales from 1e-3 to 1e6; boxes about
// a point on one lane's ray, near the rays, flat (as a ground quad's), and
// far (coordinates up to 1e6). Wherever a ray enters a box (in double
// precision) entry(), with the growth grow_for gives for the boxes' scene
// with or without the caller's slack, is not +inf and is no later than the
// first ray's entry parameter, and so with a parameter limit for the rays
// that enter by the limit. On an axis of one direction sign, crossing_lo and
// crossing_hi of a plane offset by the growth (as the kd-tree walk offsets
// its split planes) hold every ray's crossing of the plane.
TEST(IntervalBound, NeverCullsABoxARayEntersNorBoundsItsEntryLate) {
  std::mt19937 g(31);
  std::size_t boxes = 0, entered = 0, culled = 0, limited = 0, crossings = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    RaySet rays(1 + static_cast<int>(g() % 8));
    const float scale = std::pow(10.0f, -3.0f + 9.0f * unit(g));
    const Vec3 base = scale * random_vec(g);
    const Vec3 aim = random_vec(g);
    const bool shared = trial % 3 == 0;
    const int mode = (trial / 3) % 4;
    const float set_magnitude = trial % 5 == 0 ? std::pow(10.0f, -20.0f + 40.0f * unit(g)) : 1.0f;
    const int zero_axis = trial % 7 == 0 ? static_cast<int>(g() % 3) : -1;
    const bool finite_t = trial % 2 == 0;
    const float reach = 4.0f * scale;
    // Per lane, the parameter span over which it travels `reach`.
    std::vector<float> span(rays.n);
    for (std::size_t k = 0; k < rays.n; ++k) {
      const Vec3 origin = shared ? base : base + scale * random_vec(g);
      // Coherent about `aim` (one sign per axis, mostly), or of both signs.
      Vec3 dir = mode == 1 ? random_vec(g) : aim + 0.05f * random_vec(g);
      dir *= mode == 2 ? std::pow(10.0f, -20.0f + 40.0f * unit(g)) : set_magnitude;
      if (mode == 3) {
        // Exactly zero, or below what the bound takes a reciprocal of.
        const int a = static_cast<int>(g() % 3);
        const float pick = unit(g);
        if (pick < 0.3f) {
          dir[a] = 0.0f;
        } else if (pick < 0.6f) {
          dir[a] = std::copysign(1e-35f, dir[a]);
        }
      }
      if (zero_axis >= 0) dir[zero_axis] = 0.0f;
      if (trial % 11 == 0 && k == 3) dir = Vec3(0.0f);  // a ray that stays at its origin
      const float length = max_abs(dir);
      const float travel = length > 0.0f ? reach / length : 0.0f;
      span[k] = std::isfinite(travel) ? travel : 0.0f;
      const float t_min = trial % 4 == 1 ? 0.2f * span[k] * unit(g) : 0.0f;
      const float t_max = finite_t ? t_min + span[k] * (0.1f + unit(g)) : kInf;
      rays.put(k, origin, dir, t_min, t_max);
    }
    for (std::uint8_t& bits : rays.lanes) bits = static_cast<std::uint8_t>(trial % 6 == 0 ? g() & 0xFFu : 0xFFu);
    rays.lanes[0] = static_cast<std::uint8_t>(rays.lanes[0] | 1u);
    const std::vector<std::size_t> active = rays.active();

    std::vector<Aabb> cells;
    Aabb scene_box = Aabb::empty();
    for (int b = 0; b < 20; ++b) {
      const int kind = b % 5;
      Vec3 centre, half;
      if (kind <= 1) {
        // About a point on a live lane's ray, within its t range.
        const std::size_t k = active[g() % active.size()];
        const float t_end = rays.t1[k] == kInf ? rays.t0[k] + span[k] : rays.t1[k];
        const float t = rays.t0[k] + (t_end - rays.t0[k]) * unit(g);
        centre = rays.origin_of(k) + t * rays.direction_of(k);
        const float size = max_abs(centre) + scale;
        half = size * Vec3(1e-4f + 0.3f * unit(g), 1e-4f + 0.3f * unit(g), 1e-4f + 0.3f * unit(g));
      } else if (kind <= 3) {
        centre = base + 2.0f * scale * random_vec(g);
        half = scale * Vec3(0.01f + 0.5f * unit(g), 0.01f + 0.5f * unit(g), 0.01f + 0.5f * unit(g));
        if (kind == 3) half[static_cast<int>(g() % 3)] = 0.0f;  // flat
      } else {
        centre = 1e6f * random_vec(g);
        half = 5e4f * Vec3(unit(g), unit(g), unit(g));
      }
      cells.push_back(Aabb{centre - half, centre + half});
      scene_box.extend(cells.back().lower);
      scene_box.extend(cells.back().upper);
    }

    const rt::IntervalBound bound(rays.ranges());
    const float slack = trial % 4 == 3 ? 1e-6f * scale : 0.0f;
    const rt::IntervalBound::Growth grow = bound.grow_for(scene_box, slack);
    for (std::size_t b = 0; b < cells.size(); ++b) {
      const Aabb& cell = cells[b];
      const std::size_t k_limit = active[g() % active.size()];
      const float limit_span = rays.t1[k_limit] == kInf ? span[k_limit] : rays.t1[k_limit] - rays.t0[k_limit];
      const float limit = rays.t0[k_limit] + 1.5f * unit(g) * limit_span;
      double first = kNoEntry, first_by_limit = kNoEntry;
      for (const std::size_t k : active) {
        const Vec3 o = rays.origin_of(k), d = rays.direction_of(k);
        const double t0 = static_cast<double>(rays.t0[k]), t1 = static_cast<double>(rays.t1[k]);
        first = std::min(first, entry_parameter(o, d, t0, t1, cell));
        const double t1_by_limit = std::min(t1, static_cast<double>(limit));
        first_by_limit = std::min(first_by_limit, entry_parameter(o, d, t0, t1_by_limit, cell));
      }
      const float e = bound.entry(cell, grow), e_limit = bound.entry(cell, grow, limit);
      ++boxes;
      ASSERT_FALSE(std::isnan(e)) << "trial " << trial << " box " << b;
      if (first != kNoEntry) {
        ++entered;
        ASSERT_NE(e, kInf) << "trial " << trial << " box " << b << ": a ray enters a culled box";
        ASSERT_LE(static_cast<double>(e), first) << "trial " << trial << " box " << b << ": entry bound too late";
      } else if (e == kInf) {
        ++culled;
      }
      if (first_by_limit != kNoEntry) {
        ++limited;
        ASSERT_NE(e_limit, kInf) << "trial " << trial << " box " << b << " limit " << limit;
        ASSERT_LE(static_cast<double>(e_limit), first_by_limit)
            << "trial " << trial << " box " << b << " limit " << limit;
      }
    }

    for (int a = 0; a < 3; ++a) {
      const int sign = bound.sign(a);
      if (sign == 0) continue;
      for (const std::size_t k : active) {
        ASSERT_TRUE(sign > 0 ? rays.d[a][k] > 0.0f : rays.d[a][k] < 0.0f) << "trial " << trial << " axis " << a;
      }
      for (int s = 0; s < 4; ++s) {
        const Aabb& cell = cells[g() % cells.size()];
        const float split = s % 2 == 0 ? cell.lower[a] : cell.upper[a];
        const float lo = bound.crossing_lo(a, sign > 0 ? split - grow.axis[a] : split + grow.axis[a]);
        const float hi = bound.crossing_hi(a, sign > 0 ? split + grow.axis[a] : split - grow.axis[a]);
        for (const std::size_t k : active) {
          const double crossing = (static_cast<double>(split) - static_cast<double>(rays.o[a][k])) /
                                  static_cast<double>(rays.d[a][k]);
          ++crossings;
          ASSERT_LE(static_cast<double>(lo), crossing) << "trial " << trial << " axis " << a << " lane " << k;
          ASSERT_GE(static_cast<double>(hi), crossing) << "trial " << trial << " axis " << a << " lane " << k;
        }
      }
    }
  }
  // About 40% of the boxes are built about a point on a ray; the far boxes
  // and those behind coherent sets are culled.
  EXPECT_GT(entered, boxes / 3);
  EXPECT_GT(culled, boxes / 20) << culled << " of " << boxes;
  EXPECT_GT(limited, boxes / 20);
  EXPECT_LT(limited, entered) << "some rays enter only after the limit";
  EXPECT_GT(crossings, 1000u);
}

// Useful: boxes no ray of the set can reach give +inf. Behind: every origin
// lies past the box on an axis along which every direction points away from
// it or is zero, with finite or infinite t ranges. Beyond: on an axis every
// ray crosses one way, the box starts past the farthest the set's ranges
// reach by its largest t (the origins' extreme plus t_hi times the
// directions' extreme). At scales from 1e-3 to 1e6, gaps of 1e-3 of the
// coordinates (far above the bound's rounding), with and without the
// caller's slack. The same set enters a box about its origins at t = 0.
TEST(IntervalBound, BoxesNoRayCanReachGiveInfinity) {
  std::mt19937 g(17);
  for (int trial = 0; trial < 2000; ++trial) {
    RaySet rays(1 + static_cast<int>(g() % 8));
    const float scale = std::pow(10.0f, -3.0f + 9.0f * unit(g));
    const Vec3 base = scale * random_vec(g);
    const int axis = static_cast<int>(g() % 3);
    const float away = trial % 2 == 0 ? 1.0f : -1.0f;  // every direction's sign on `axis`
    const bool beyond = trial % 4 >= 2;
    const float t_hi = 0.5f + 2.0f * unit(g);
    for (std::size_t k = 0; k < rays.n; ++k) {
      const Vec3 origin = trial % 3 == 0 ? base : base + scale * random_vec(g);
      Vec3 dir = random_vec(g);
      dir[axis] = away * (beyond ? 0.2f + unit(g) : (k % 5 == 0 ? 0.0f : unit(g)));
      dir *= scale;
      const float t_max = beyond || trial % 3 == 1 ? t_hi * (0.5f + 0.5f * unit(g)) : kInf;
      rays.put(k, origin, dir, 0.0f, t_max);
    }
    for (std::uint8_t& bits : rays.lanes) bits = static_cast<std::uint8_t>(trial % 5 == 0 ? g() & 0xFFu : 0xFFu);
    rays.lanes[0] = static_cast<std::uint8_t>(rays.lanes[0] | 1u);
    const std::vector<std::size_t> active = rays.active();
    float o_min = kInf, o_max = -kInf, d_far = 0.0f, t_far = 0.0f;
    for (const std::size_t k : active) {
      o_min = std::min(o_min, rays.o[axis][k]);
      o_max = std::max(o_max, rays.o[axis][k]);
      d_far = std::max(d_far, std::fabs(rays.d[axis][k]));
      t_far = std::max(t_far, rays.t1[k]);
    }
    const float size = scale * (0.01f + unit(g));
    Aabb box{base - Vec3(4.0f * scale), base + Vec3(4.0f * scale)};  // holds every origin
    float gap = 0.0f;
    if (!beyond) {
      gap = 1e-3f * (std::max(std::fabs(o_min), std::fabs(o_max)) + scale);
      box.upper[axis] = away > 0.0f ? o_min - gap : o_max + gap + size;
      box.lower[axis] = box.upper[axis] - size;
    } else {
      const float far_reach = t_far * d_far;
      gap = 1e-3f * (std::max(std::fabs(o_min), std::fabs(o_max)) + far_reach + scale);
      box.lower[axis] = away > 0.0f ? o_max + far_reach + gap : o_min - far_reach - gap - size;
      box.upper[axis] = box.lower[axis] + size;
    }
    // The premise, by the double-precision slab test: no ray enters.
    for (const std::size_t k : active) {
      ASSERT_EQ(entry_parameter(rays.origin_of(k), rays.direction_of(k), static_cast<double>(rays.t0[k]),
                                static_cast<double>(rays.t1[k]), box),
                kNoEntry)
          << "trial " << trial << " lane " << k;
    }
    const rt::IntervalBound bound(rays.ranges());
    const float slack = trial % 3 == 2 ? 0.125f * gap : 0.0f;
    const rt::IntervalBound::Growth grow = bound.grow_for(box, slack);
    ASSERT_EQ(bound.entry(box, grow), kInf) << "trial " << trial << (beyond ? " beyond" : " behind");
    ASSERT_EQ(bound.entry(box, grow, t_far), kInf) << "trial " << trial << (beyond ? " beyond" : " behind");

    // About the origins on every axis: entered at the start.
    Aabb around = box;
    around.lower[axis] = o_min - gap;
    around.upper[axis] = o_max + gap;
    ASSERT_EQ(bound.entry(around, bound.grow_for(around, slack)), 0.0f) << "trial " << trial;
  }
}

// By hand: eight rays along +x from x = 0 and x = 1 (y = 0 or 0.5, z = 0)
// at speeds 1 and 2, t in [0, 100]. Ahead, the box x in [10, 20] is first
// entered by the ray from x = 1 at speed 2, at t = (10 - 1) / 2 = 4.5; the
// bound lies at most its margins (2^-20 relative, growth 20 * 2^-20) below.
// No ray is there by t = 4 (the fastest is at x = 9); none reaches a box
// behind (x <= -2), beside (y in [3, 4], where no ray's y goes) or beyond
// (x >= 500: by t = 100 the fastest is at x = 201); a box about the origins
// is entered at t = 0. Mirrored along -x, the box x in [-20, -10] is first
// entered by the ray from x = 0 at speed 2, at t = 10 / 2 = 5.
TEST(IntervalBound, AnAxisAlignedSetEntersBoxesWhereComputedByHand) {
  RaySet rising(1), falling(1);
  for (std::size_t k = 0; k < 8; ++k) {
    const Vec3 origin(static_cast<float>(k % 2), 0.5f * static_cast<float>(k / 4), 0.0f);
    const float speed = (k / 2) % 2 == 0 ? 1.0f : 2.0f;
    rising.put(k, origin, Vec3(speed, 0.0f, 0.0f), 0.0f, 100.0f);
    falling.put(k, origin, Vec3(-speed, 0.0f, 0.0f), 0.0f, 100.0f);
  }
  const rt::RayRanges r = rising.ranges();
  EXPECT_EQ(r.o_lo[0], 0.0f);
  EXPECT_EQ(r.o_hi[0], 1.0f);
  EXPECT_EQ(r.o_lo[1], 0.0f);
  EXPECT_EQ(r.o_hi[1], 0.5f);
  EXPECT_EQ(r.o_lo[2], 0.0f);
  EXPECT_EQ(r.o_hi[2], 0.0f);
  EXPECT_EQ(r.d_lo[0], 1.0f);
  EXPECT_EQ(r.d_hi[0], 2.0f);
  for (int a = 1; a < 3; ++a) {
    EXPECT_EQ(r.d_lo[a], 0.0f) << a;
    EXPECT_EQ(r.d_hi[a], 0.0f) << a;
  }
  EXPECT_EQ(r.t_lo, 0.0f);
  EXPECT_EQ(r.t_hi, 100.0f);
  EXPECT_TRUE(r.finite);
  EXPECT_EQ(r.origin_magnitude(), 1.0f);

  const rt::IntervalBound bound(r);
  EXPECT_EQ(bound.t_lo(), 0.0f);
  EXPECT_EQ(bound.t_hi(), 100.0f);
  EXPECT_EQ(bound.sign(0), 1);
  EXPECT_EQ(bound.sign(1), 0) << "zero directions bound nothing";
  EXPECT_EQ(bound.sign(2), 0);

  const Aabb ahead{Vec3(10.0f, -5.0f, -5.0f), Vec3(20.0f, 5.0f, 5.0f)};
  // Per axis 2^-20 of the larger of the box's and the origins' magnitudes,
  // plus the caller's slack.
  const rt::IntervalBound::Growth grow = bound.grow_for(ahead, 0.0f);
  EXPECT_EQ(grow.axis[0], 20.0f * 0x1.0p-20f);
  EXPECT_EQ(grow.axis[1], 5.0f * 0x1.0p-20f);
  EXPECT_EQ(grow.axis[2], 5.0f * 0x1.0p-20f);
  alignas(16) float v[4];
  grow.v.store(v);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(v[a], grow.axis[a]) << a;
  EXPECT_EQ(v[3], 0.0f);
  EXPECT_EQ(bound.grow_for(ahead, 0.25f).axis[0], 0.25f + 20.0f * 0x1.0p-20f);
  RaySet far_origins(1);
  for (std::size_t k = 0; k < 8; ++k) far_origins.put(k, Vec3(1000.0f, 0.0f, 0.0f), Vec3(1.0f), 0.0f, 1.0f);
  EXPECT_EQ(rt::IntervalBound(far_origins.ranges()).grow_for(ahead, 0.0f).axis[0], 1000.0f * 0x1.0p-20f)
      << "origins larger than the box set the growth";

  const float e = bound.entry(ahead, grow);
  EXPECT_LE(e, 4.5f);
  EXPECT_GE(e, 4.5f - 1e-4f);
  EXPECT_EQ(bound.entry(ahead, grow, 5.0f), e);
  EXPECT_EQ(bound.entry(ahead, grow, 4.0f), kInf) << "by t = 4 the fastest ray is at x = 9";
  // Crossing x = 10: first at t = 4.5, last at t = 10 (from x = 0 at speed 1).
  EXPECT_LE(bound.crossing_lo(0, 10.0f), 4.5f);
  EXPECT_GE(bound.crossing_lo(0, 10.0f), 4.5f - 1e-4f);
  EXPECT_GE(bound.crossing_hi(0, 10.0f), 10.0f);
  EXPECT_LE(bound.crossing_hi(0, 10.0f), 10.0f + 1e-4f);

  const Aabb behind{Vec3(-10.0f, -5.0f, -5.0f), Vec3(-2.0f, 5.0f, 5.0f)};
  const Aabb beside{Vec3(10.0f, 3.0f, -5.0f), Vec3(20.0f, 4.0f, 5.0f)};
  const Aabb beyond{Vec3(500.0f, -5.0f, -5.0f), Vec3(600.0f, 5.0f, 5.0f)};
  EXPECT_EQ(bound.entry(behind, bound.grow_for(behind, 0.0f)), kInf);
  EXPECT_EQ(bound.entry(beside, bound.grow_for(beside, 0.0f)), kInf);
  EXPECT_EQ(bound.entry(beyond, bound.grow_for(beyond, 0.0f)), kInf);
  const Aabb around{Vec3(-1.0f, -1.0f, -1.0f), Vec3(2.0f, 1.0f, 1.0f)};
  EXPECT_EQ(bound.entry(around, bound.grow_for(around, 0.0f)), 0.0f);

  const rt::IntervalBound mirrored(falling.ranges());
  EXPECT_EQ(mirrored.sign(0), -1);
  const Aabb ahead_of_falling{Vec3(-20.0f, -5.0f, -5.0f), Vec3(-10.0f, 5.0f, 5.0f)};
  const float m = mirrored.entry(ahead_of_falling, mirrored.grow_for(ahead_of_falling, 0.0f));
  EXPECT_LE(m, 5.0f);
  EXPECT_GE(m, 5.0f - 1e-4f);
  const Aabb behind_falling{Vec3(2.0f, -5.0f, -5.0f), Vec3(10.0f, 5.0f, 5.0f)};
  EXPECT_EQ(mirrored.entry(behind_falling, mirrored.grow_for(behind_falling, 0.0f)), kInf);
}

// RangeAccumulator keeps the ranges of the lanes in each group's mask only:
// the others may hold anything (huge, infinite, NaN), as a packet's dead
// lanes do, and a group with no lanes adds nothing. An infinite t1 is a
// range, not a non-finite ray; a non-finite origin, direction or t0 in a
// live lane makes the set bound nothing, so that every box may be entered
// (entry -inf, even for a box no finite ray could reach).
TEST(IntervalBound, RangesHoldTheLiveLanesAndNonFiniteRaysBoundNothing) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::mt19937 g(5);
  RaySet rays(2);
  rays.lanes = {std::uint8_t{0b01011010}, std::uint8_t{0b10000001}};
  for (std::size_t k = 0; k < rays.n; ++k) {
    if (rays.on(k)) {
      rays.put(k, 10.0f * random_vec(g), random_vec(g), unit(g), 1.0f + 10.0f * unit(g));
    } else {
      rays.put(k, Vec3(1e30f, -1e30f, nan), Vec3(nan, kInf, -kInf), -kInf, nan);
    }
  }
  rays.t1[6] = kInf;  // a live lane without an end
  ASSERT_TRUE(rays.on(6));

  rt::RangeAccumulator acc;
  EXPECT_TRUE(acc.empty());
  const Vec3x8 zero{Float8(0.0f), Float8(0.0f), Float8(0.0f)};
  acc.add(zero, zero, Float8(0.0f), Float8(1.0f), 0u);
  EXPECT_TRUE(acc.empty()) << "no lanes, nothing added";
  rays.add_to(acc);
  EXPECT_FALSE(acc.empty());
  const rt::RayRanges r = acc.ranges();

  float o_lo[3] = {kInf, kInf, kInf}, o_hi[3] = {-kInf, -kInf, -kInf};
  float d_lo[3] = {kInf, kInf, kInf}, d_hi[3] = {-kInf, -kInf, -kInf};
  float t_lo = kInf, t_hi = -kInf, magnitude = 0.0f;
  for (const std::size_t k : rays.active()) {
    for (int a = 0; a < 3; ++a) {
      o_lo[a] = std::min(o_lo[a], rays.o[a][k]);
      o_hi[a] = std::max(o_hi[a], rays.o[a][k]);
      d_lo[a] = std::min(d_lo[a], rays.d[a][k]);
      d_hi[a] = std::max(d_hi[a], rays.d[a][k]);
      magnitude = std::max(magnitude, std::fabs(rays.o[a][k]));
    }
    t_lo = std::min(t_lo, rays.t0[k]);
    t_hi = std::max(t_hi, rays.t1[k]);
  }
  EXPECT_EQ(rays.active().size(), 6u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(r.o_lo[a], o_lo[a]) << a;
    EXPECT_EQ(r.o_hi[a], o_hi[a]) << a;
    EXPECT_EQ(r.d_lo[a], d_lo[a]) << a;
    EXPECT_EQ(r.d_hi[a], d_hi[a]) << a;
  }
  EXPECT_EQ(r.t_lo, t_lo);
  EXPECT_EQ(r.t_hi, kInf);
  EXPECT_EQ(t_hi, kInf);
  EXPECT_TRUE(r.finite) << "dead lanes and an infinite t1 are no non-finite ray";
  EXPECT_EQ(r.origin_magnitude(), magnitude);
  const rt::IntervalBound bound(r);
  EXPECT_EQ(bound.t_lo(), t_lo);
  EXPECT_EQ(bound.t_hi(), kInf);

  const Aabb far{Vec3(1e5f), Vec3(1e5f + 1.0f)};
  for (int what = 0; what < 4; ++what) {
    RaySet poisoned = rays;
    const std::size_t k = 4;  // live
    ASSERT_TRUE(poisoned.on(k));
    if (what == 0) poisoned.o[1][k] = nan;
    if (what == 1) poisoned.d[2][k] = kInf;
    if (what == 2) poisoned.d[0][k] = nan;
    if (what == 3) poisoned.t0[k] = nan;
    const rt::RayRanges pr = poisoned.ranges();
    EXPECT_FALSE(pr.finite) << what;
    const rt::IntervalBound unbounded(pr);
    EXPECT_EQ(unbounded.entry(far, unbounded.grow_for(far, 0.0f)), -kInf) << what;
  }
}

// slab_passage: the latest per-axis entry and the earliest exit (lane 3
// unused, -inf and +inf), clipped to [t_lo, t_hi]; empty when the entry
// comes after the exit. Each axis in turn holds the latest entry and the
// earliest exit.
TEST(IntervalBound, SlabPassageRunsFromTheLatestEntryToTheEarliestExit) {
  const auto passage = [](float e0, float e1, float e2, float l0, float l1, float l2, float t_lo, float t_hi) {
    return rt::slab_passage(Float4(Vec3(e0, e1, e2), -kInf), Float4(Vec3(l0, l1, l2), kInf), t_lo, t_hi);
  };
  struct Case {
    float enter[3], leave[3], t_lo, t_hi;
    float want_enter, want_leave;  // NaN: empty (entry after exit)
  };
  const float empty = std::numeric_limits<float>::quiet_NaN();
  const Case cases[] = {
      {{1, 3, 2}, {10, 5, 7}, 0, 8, 3, 5},
      {{6, -1, 2}, {7, 9, 8}, 0, 8, 6, 7},
      {{0, 0.5f, 9}, {20, 11, 10}, 0, 30, 9, 10},
      // Clipped to the parameter range.
      {{1, 3, 2}, {10, 5, 7}, 4, 8, 4, 5},
      {{1, 3, 2}, {10, 5, 7}, 0, 4.5f, 3, 4.5f},
      // Empty: the range ends before the entry, or an axis is left before
      // another is entered.
      {{1, 3, 2}, {10, 5, 7}, 0, 2, empty, empty},
      {{6, 0, 0}, {10, 5, 7}, 0, 8, empty, empty},
      // Unbounded axes leave the parameter range.
      {{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}, 0.25f, 3, 0.25f, 3},
  };
  for (const Case& c : cases) {
    const rt::SlabPassage p = passage(c.enter[0], c.enter[1], c.enter[2], c.leave[0], c.leave[1], c.leave[2],
                                      c.t_lo, c.t_hi);
    if (std::isnan(c.want_enter)) {
      EXPECT_GT(p.enter, p.leave) << c.enter[0] << " " << c.t_hi;
      continue;
    }
    EXPECT_EQ(p.enter, c.want_enter) << c.enter[0] << " " << c.t_hi;
    EXPECT_EQ(p.leave, c.want_leave) << c.enter[0] << " " << c.t_hi;
  }
}

// What the bound must keep is what a lane's own walk keeps: the single ray
// clips a box grown by its world slack (traverse/ray_frames.h), so it enters
// boxes it passes within that slack of. Rays along an axis from one origin,
// boxes beside them by half a lane's slack (at scales from 1e-3 to 1e6):
// every such box the single ray's clip enters, entry() with the growth a
// packet uses (grow_for with traversal_slack_bound, as large_packet.cpp's
// run()) keeps. Without the growth the bound would cull them all.
TEST(IntervalBound, KeepsTheBoxesALanesSlackedClipEnters) {
  std::mt19937 g(77);
  std::size_t kept = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const float scale = std::pow(10.0f, -3.0f + 9.0f * unit(g));
    const Vec3 origin = scale * random_vec(g);
    const int axis = static_cast<int>(g() % 3), side = (axis + 1) % 3;
    Vec3 dir(0.0f);
    dir[axis] = (g() & 1u) ? 1.0f : -1.0f;
    RaySet rays(1);
    const float t_max = 2.0f * scale;
    for (std::size_t k = 0; k < 8; ++k) rays.put(k, origin, dir, 0.0f, t_max);
    // A box around a point of the ray at t in (0, t_max), beside the ray on
    // `side` by half the slack the single ray grows it by.
    const Vec3 at = origin + (0.5f * t_max) * dir;
    const Vec3 half(0.05f * scale);
    Aabb box{at - half, at + half};
    const float eps = rt::per_lane::world_slack<float>(max_abs(origin), 1.0f, max_abs(box), t_max);
    const float shift = half[side] + 0.5f * eps;
    box.lower[side] += shift;
    box.upper[side] += shift;
    ASSERT_EQ(entry_parameter(origin, dir, 0.0, static_cast<double>(t_max), box), kNoEntry) << "trial " << trial;
    float c0 = 0.0f, c1 = t_max;
    const Vec3 inv(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
    const float slack_here = rt::per_lane::world_slack<float>(max_abs(origin), 1.0f, max_abs(box), t_max);
    if (!rt::per_lane::clip_to_box<float>(box, slack_here, origin, dir, inv, c0, c1)) continue;
    ++kept;
    const rt::IntervalBound bound(rays.ranges());
    Aabb scene_box = box;
    scene_box.extend(origin);
    const float slack = rt::traversal_slack_bound(max_abs(origin), 1.0f, t_max, max_abs(scene_box));
    ASSERT_NE(bound.entry(box, bound.grow_for(scene_box, slack)), kInf) << "trial " << trial << " scale " << scale;
  }
  EXPECT_GT(kept, 300u);
}

}  // namespace
}  // namespace sinew
