// The stochastic rays of a tile: one sample of an area light, or one
// ambient occlusion ray, per hit, eight lanes at a time, placed as
// segments for trace_shadow_rays (docs/RAYTRACE.md, "Soft shadows and
// ambient occlusion").
#include <bit>
#include <cmath>

#include "raytrace/render/sampling/sample_pattern.h"
#include "raytrace/render/stages/stage_support.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/traverse/traversal_shared.h"

namespace sinew::rt {

using namespace stages;

namespace {

Vec3x8 splat(const Vec3& v) { return {Float8(v.x), Float8(v.y), Float8(v.z)}; }

// Two unit vectors completing unit `n` to an orthonormal basis, without a
// branch (Duff et al. 2017, "Building an orthonormal basis, revisited").
void complete_basis(const Vec3x8& n, Vec3x8& t1, Vec3x8& t2) {
  const Float8 sign = select(n.z >= Float8(0.0f), Float8(1.0f), Float8(-1.0f));
  const Float8 a = Float8(-1.0f) / (sign + n.z);
  const Float8 b = n.x * n.y * a;
  t1 = {Float8(1.0f) + sign * n.x * n.x * a, sign * b, -(sign * n.x)};
  t2 = {b, sign + n.y * n.y * a, -n.y};
}

// x rounded to the nearest integer (|x| < 2^22): the sum with 1.5 * 2^23
// has no fraction bits left.
Float8 round_to_integer(Float8 x) {
  const Float8 magic(12582912.0f);
  return (x + magic) - magic;
}
Float8 sign_of(Float8 x) { return select(x >= Float8(0.0f), Float8(1.0f), Float8(-1.0f)); }

// The octahedron's fold between its upper and lower halves (its own
// inverse): (x, y) -> ((1 - |y|) sign x, (1 - |x|) sign y), where `fold`.
void fold_octahedron(Mask8 fold, Float8& x, Float8& y) {
  const Float8 one(1.0f);
  const Float8 fx = (one - abs(y)) * sign_of(x), fy = (one - abs(x)) * sign_of(y);
  x = select(fold, fx, x);
  y = select(fold, fy, y);
}

// A sphere light's disk turns towards each hit in steps: its axis is the
// direction from the hit snapped to a grid of `steps` points per unit on the
// octahedron (|x| + |y| + |z| = 1, the lower half folded over), so that the
// hits of one grid cell share one disk and, in a round, a sample class
// takes one point of the light. `steps` is a power of two
// (RenderSettings::sphere_disk_steps), so dividing by it is exact. Returns
// the unit vector of the grid point nearest non-zero `w`.
Vec3x8 snapped_axis(const Vec3x8& w, int steps) {
  const Float8 one(1.0f), grid(static_cast<float>(steps)), cell(1.0f / static_cast<float>(steps));
  const Float8 to_octahedron = one / (abs(w.x) + abs(w.y) + abs(w.z));
  Float8 x = w.x * to_octahedron, y = w.y * to_octahedron;
  fold_octahedron(w.z < Float8(0.0f), x, y);
  // Exact: the grid is a power of two.
  x = round_to_integer(x * grid) * cell;
  y = round_to_integer(y * grid) * cell;
  const Float8 z = one - abs(x) - abs(y);
  fold_octahedron(z < Float8(0.0f), x, y);
  const Float8 inverse = one / sqrt(x * x + y * y + z * z);
  return {x * inverse, y * inverse, z * inverse};
}

// Sample j of n of every lane (render/sampling/sample_pattern.h), on the
// unit square and on the unit disk.
struct LaneSamples {
  Float8 u, v;    // the square
  Float8 dx, dy;  // the disk
};
LaneSamples lane_samples(const TileScratch& s, std::size_t k0, const LatticeSample& base, int j, int n) {
  LaneSamples out;
  const Float8 xi = Float8::load(&s.shift_xi[k0]);
  out.u = (Float8(static_cast<float>(j)) + xi) / Float8(static_cast<float>(n));
  const Float8 v = Float8(base.v0) + Float8::load(&s.shift_eta[k0]);
  out.v = select(v >= Float8(1.0f), v - Float8(1.0f), v);
  const Float8 c = Float8::load(&s.shift_cos[k0]), sn = Float8::load(&s.shift_sin[k0]);
  const Float8 r = sqrt(out.u);
  out.dx = r * (Float8(base.cos_v0) * c - Float8(base.sin_v0) * sn);
  out.dy = r * (Float8(base.sin_v0) * c + Float8(base.cos_v0) * sn);
  return out;
}

// Starts a round of segment rays with t in [0, t_max).
void start_segments(float t_max, TileScratch& s) {
  s.shadow_placed = 0;
  s.shadows_compacted = false;
  s.shadow_count = 0;
  s.shadow_region_begin.clear();
  s.shadows_from_point = false;
  s.shadows_per_lane = true;
  s.segments_share_origins = false;
  s.shadows_aimed_only = false;
  s.shadow_ends = Aabb::empty();
  s.shadow_tmax = t_max;
}

// Block b's rays for `lanes` (the others lose bit l of s.lit): from their
// origins along their directions.
void place_block(TileScratch& s, std::size_t b, std::uint32_t hits, std::uint32_t lanes, int l,
                 const Vec3x8& origin, const Vec3x8& direction) {
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  const std::size_t k0 = b * kBlockLanes;
  for (std::uint32_t away = hits & ~lanes; away != 0; away &= away - 1) {
    s.lit[k0 + static_cast<std::size_t>(std::countr_zero(away))] &= dark;
  }
  s.shadow_lanes[b] = static_cast<std::uint8_t>(lanes);
  if (lanes == 0) return;
  store3(origin, s.shadow_from_x, s.shadow_from_y, s.shadow_from_z, k0);
  store3(direction, s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
  s.shadow_placed += static_cast<std::size_t>(std::popcount(lanes));
}

// A ray from a point on the light to block k0's hits: its far end is the
// hit pushed off as a point light's ray pushes it and clear of the
// traversal's slack (slack_clearance: the light's share of that slack is
// within the point light's push already), one float further.
void place_from_points(TileScratch& s, std::size_t b, std::uint32_t hits, int l, const Vec3x8& from) {
  const std::size_t k0 = b * kBlockLanes;
  const Vec3x8 position = load3(s.px, s.py, s.pz, k0);
  const std::uint32_t facing =
      (dot(load3(s.gx, s.gy, s.gz, k0), from - position) > Float8(0.0f)).bits() & hits;
  const Float8 magnitude = max(max(abs(from.x), abs(from.y)), abs(from.z));
  const Vec3x8 push = surface_push_from(s, k0, from, magnitude, slack_clearance(s, Float8(0.0f)));
  const Vec3x8 moved = position + push;
  const Vec3x8 end{step_away(moved.x, push.x), step_away(moved.y, push.y), step_away(moved.z, push.z)};
  place_block(s, b, hits, facing, l, from, end - from);
}

// A ray from block k0's hits, pushed off as a directional light's ray
// starts and clear of the traversal's slack for rays reaching `reach`
// (slack_clearance), along `direction`; those leaving below the surface
// are dropped.
void place_from_hits(TileScratch& s, std::size_t b, std::uint32_t hits, int l, const Vec3x8& direction,
                     Float8 reach) {
  const std::size_t k0 = b * kBlockLanes;
  const std::uint32_t facing = (dot(load3(s.gx, s.gy, s.gz, k0), direction) > Float8(0.0f)).bits() & hits;
  const Vec3x8 push = surface_push(s, k0, Float8::load(&s.error[k0]) + slack_clearance(s, reach));
  const Vec3x8 moved = load3(s.px, s.py, s.pz, k0) + push;
  const Vec3x8 origin{step_away(moved.x, push.x), step_away(moved.y, push.y), step_away(moved.z, push.z)};
  place_block(s, b, hits, facing, l, origin, direction);
}

}  // namespace

void shift_pixels(std::uint32_t seed, std::uint32_t stream, TileScratch& s) {
  // A pixel's shift depends on its sample class alone, and every block
  // starts a whole number of interleaving blocks from the tile's corner
  // (compact_by_class relies on the same), so the first block's eight
  // shifts are every block's.
  static_assert(kBlockWidth % kInterleave == 0 && (kBlockLanes / kBlockWidth) % kInterleave == 0);
  alignas(32) float xi[kBlockLanes], eta[kBlockLanes], cos_eta[kBlockLanes], sin_eta[kBlockLanes];
  for (int lane = 0; lane < kBlockLanes; ++lane) {
    const std::size_t k = static_cast<std::size_t>(lane);
    const PixelShift shift = pixel_shift(seed, stream, s.pixel_x(k), s.pixel_y(k));
    xi[lane] = shift.xi;
    eta[lane] = shift.eta;
    cos_eta[lane] = shift.cos_eta;
    sin_eta[lane] = shift.sin_eta;
  }
  const Float8 block_xi = Float8::load(xi), block_eta = Float8::load(eta);
  const Float8 block_cos = Float8::load(cos_eta), block_sin = Float8::load(sin_eta);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    if (s.block_hits[b] == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    block_xi.store(&s.shift_xi[k0]);
    block_eta.store(&s.shift_eta[k0]);
    block_cos.store(&s.shift_cos[k0]);
    block_sin.store(&s.shift_sin[k0]);
  }
}

void place_light_samples(const Light& light, int disk_steps, int l, int j, int n, TileScratch& s) {
  const bool sun = light.kind == Light::Kind::kDirectional;
  start_segments(sun ? kInf : 1.0f, s);
  s.segments_share_origins = !sun;
  const LatticeSample base = lattice_sample(j);
  const Vec3x8 centre = splat(light.position);
  // The sun: directions through a disk of radius tan(angular radius) one
  // unit along the light's unit direction.
  const Vec3 sun_axis = glm::normalize(light.direction);
  Vec3x8 sun_t1, sun_t2;
  complete_basis(splat(sun_axis), sun_t1, sun_t2);
  const Float8 sun_spread(std::tan(light.angular_radius));
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t hits = s.block_hits[b];
    if (hits == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    const LaneSamples sample = lane_samples(s, k0, base, j, n);
    switch (light.kind) {
      case Light::Kind::kPoint: {
        // A sphere light: points uniform on its disk facing the hit, the
        // disk's axis snapped (snapped_axis) or, with no steps, the hit's own.
        const Vec3x8 w = centre - load3(s.px, s.py, s.pz, k0);
        Vec3x8 facing;
        Mask8 apart;
        if (disk_steps > 0) {
          apart = (abs(w.x) + abs(w.y) + abs(w.z)) > Float8(0.0f);
          facing = snapped_axis(w, disk_steps);
        } else {
          const Float8 length = sqrt(dot(w, w));
          apart = length > Float8(0.0f);
          const Float8 inverse = Float8(1.0f) / length;
          facing = {inverse * w.x, inverse * w.y, inverse * w.z};
        }
        const Vec3x8 axis{select(apart, facing.x, Float8(0.0f)), select(apart, facing.y, Float8(0.0f)),
                          select(apart, facing.z, Float8(1.0f))};
        Vec3x8 t1, t2;
        complete_basis(axis, t1, t2);
        const Float8 rx = Float8(light.radius) * sample.dx, ry = Float8(light.radius) * sample.dy;
        place_from_points(s, b, hits, l, centre + rx * t1 + ry * t2);
        break;
      }
      case Light::Kind::kRect: {
        const Float8 su = sample.u - Float8(0.5f), sv = sample.v - Float8(0.5f);
        place_from_points(s, b, hits, l, centre + su * splat(light.edge_u) + sv * splat(light.edge_v));
        break;
      }
      case Light::Kind::kDirectional: {
        const Vec3x8 direction = splat(sun_axis) + (sun_spread * sample.dx) * sun_t1 + (sun_spread * sample.dy) * sun_t2;
        place_from_hits(s, b, hits, l, direction, Float8(s.scene_magnitude));
        break;
      }
    }
  }
}

void place_ao_rays(float radius, int l, int j, int n, TileScratch& s) {
  start_segments(1.0f, s);
  const LatticeSample base = lattice_sample(j);
  const Float8 length(radius);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t hits = s.block_hits[b];
    if (hits == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    const LaneSamples sample = lane_samples(s, k0, base, j, n);
    // Cosine distributed about the normal: the disk point lifted onto the
    // hemisphere (Malley's method).
    const Vec3x8 g = load3(s.gx, s.gy, s.gz, k0);
    Vec3x8 t1, t2;
    complete_basis(g, t1, t2);
    const Float8 lift = sqrt(max(Float8(1.0f) - sample.dx * sample.dx - sample.dy * sample.dy, Float8(0.0f)));
    const Vec3x8 direction = sample.dx * t1 + sample.dy * t2 + lift * g;
    place_from_hits(s, b, hits, l, length * direction, length);
  }
}

void set_lit_bit(int l, TileScratch& s) {
  const std::uint8_t bit = static_cast<std::uint8_t>(1u << l);
  for (std::size_t k = 0; k < s.lanes; ++k) s.lit[k] |= bit;
}

void count_unblocked(int l, float weight, float* fraction, const TileScratch& s) {
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t hits = s.block_hits[b];
    if (hits == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    const Mask8 open = Mask8::from_bits(lane_bits(&s.lit[k0], l) & hits);
    (Float8::load(&fraction[k0]) + select(open, Float8(weight), Float8(0.0f))).store(&fraction[k0]);
  }
}

}  // namespace sinew::rt
