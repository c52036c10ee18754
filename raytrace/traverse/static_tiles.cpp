#include "raytrace/traverse/static_tiles.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "raytrace/geometry/triangle_intersect8.h"
#include "raytrace/traverse/ray_frames.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/math/float8.h"

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Triangle t of `mesh` onto the tile's list.
void add_triangle(const Scene::StaticMesh& mesh, std::uint32_t t, bool first, StaticTile& tile) {
  const auto& v = mesh.desc.triangles[t];
  const Vec3& p0 = mesh.desc.positions[v[0]];
  const Vec3& p1 = mesh.desc.positions[v[1]];
  const Vec3& p2 = mesh.desc.positions[v[2]];
  tile.triangles.push_back({p0, p1, p2, t, mesh.instance_id, detail::zero_area(p1 - p0, p2 - p0), first});
}

// Of a larger mesh, the triangles in the cells of its tree that the bound
// reaches, whose own box it may enter, ascending; false past `room`.
bool gather_reached(const Scene::StaticMesh& mesh, const RayBound::Test& test, float grow, std::size_t room,
                    const TileCone& cone, StaticTile& tile) {
  thread_local std::vector<std::uint32_t> reached;
  reached.clear();
  const KdTreeView tree = mesh.tree.view();
  bool fits = true;
  for_each_reached_leaf(tree, test, grow, [&](std::uint32_t first, std::uint32_t count) {
    for (std::uint32_t i = 0; i < count && fits; ++i) {
      const std::uint32_t t = tree.items[first + i];
      if (std::find(reached.begin(), reached.end(), t) != reached.end()) continue;  // listed in an earlier leaf
      const auto& v = mesh.desc.triangles[t];
      Aabb box = Aabb::empty();
      for (const std::uint32_t corner : v) box.extend(mesh.desc.positions[corner]);
      if (!test.may_enter(box, grow)) continue;
      if (cone.misses(mesh.desc.positions[v[0]], mesh.desc.positions[v[1]], mesh.desc.positions[v[2]])) continue;
      reached.push_back(t);
      fits = reached.size() <= room;
    }
    return fits;  // past the limit the tile takes the packets: stop walking
  });
  if (!fits) return false;
  std::sort(reached.begin(), reached.end());
  for (std::size_t i = 0; i < reached.size(); ++i) add_triangle(mesh, reached[i], i == 0, tile);
  return true;
}

}  // namespace

TileCone::TileCone(const Vec3& apex, const Vec3* directions, int count) : apex_(apex) {
  count = std::clamp(count, 0, 8);
  if (count == 0) return;
  alignas(32) float q[3][8];
  for (int i = 0; i < 8; ++i) {
    const Vec3& d = directions[std::min(i, count - 1)];
    const float length = std::sqrt(glm::dot(d, d));
    if (!(length > 0.0f) || !std::isfinite(length)) return;
    directions_[static_cast<std::size_t>(i)] = d / length;
    for (int a = 0; a < 3; ++a) q[a][i] = d[a];
  }
  count_ = count;
  frustum_.reset(apex, 1);
  frustum_.set_group(0, q, 0xFFu);
  on_ = true;
}

bool TileCone::misses(const Vec3& p0, const Vec3& p1, const Vec3& p2) const {
  if (!on_) return false;
  if (frustum_.reached(p0, p1, p2, 1u) == 0) return true;
  // Every ray beyond one edge plane: the ray meets the triangle's plane at
  // least the apex's distance h from it along the ray, so beyond the edge
  // plane by h times its slope past the plane; culled only when that
  // exceeds kConeEdgeMargin of the magnitudes. In double: the products of
  // floats are exact there.
  using D3 = glm::dvec3;
  const D3 o(apex_);
  const D3 a = D3(p0) - o, b = D3(p1) - o, c = D3(p2) - o;
  const D3 normal = glm::cross(b - a, c - a);
  const double normal_length = glm::length(normal);
  if (!(normal_length > 0.0) || !std::isfinite(normal_length)) return false;
  const double h = std::fabs(glm::dot(normal, a)) / normal_length;
  const float corners = std::max({detail::max_abs(p0), detail::max_abs(p1), detail::max_abs(p2)});
  const double magnitude = static_cast<double>(corners) + static_cast<double>(detail::max_abs(apex_));
  const double margin = kConeEdgeMargin * magnitude;
  if (!(h > margin)) return false;
  const double slope = margin / h;
  const D3* const corner[3] = {&a, &b, &c};
  for (int e = 0; e < 3; ++e) {
    const D3& x = *corner[e];
    const D3& y = *corner[(e + 1) % 3];
    const D3& z = *corner[(e + 2) % 3];
    D3 n = glm::cross(x, y);
    const double n_length = glm::length(n);
    if (!(n_length > 0.0)) continue;
    n /= n_length;
    const double inside = glm::dot(n, z);
    if (inside == 0.0) continue;
    if (inside < 0.0) n = -n;
    bool beyond = true;
    for (int i = 0; i < count_ && beyond; ++i) {
      beyond = glm::dot(n, D3(directions_[static_cast<std::size_t>(i)])) < -slope;
    }
    if (beyond) return true;
  }
  return false;
}

bool gather_static_tile(const Scene& scene, TriangleTest test, const RayBound& bound, float extra_grow,
                        std::span<const std::uint32_t> objects, StaticTile& tile, const TileCone& cone) {
  tile.triangles.clear();
  tile.meshes = 0;
  if (test != TriangleTest::kFast || objects.empty() || bound.empty()) return false;
  const std::span<const TopLevelObject> all = scene.top_level().objects();
  if (!std::all_of(objects.begin(), objects.end(),
                   [&](std::uint32_t o) { return all[o].kind == TopLevelObject::Kind::kStatic; })) {
    return false;
  }
  const RayBound::Test box_test = bound.test();
  // The grow cull_objects uses: the largest slack of any box in the scene.
  const float grow = bound.world_slack_bound(detail::max_abs(scene.top_level().bounds())) + extra_grow;
  for (const std::uint32_t object : objects) {
    const Scene::StaticMesh& mesh = scene.static_meshes()[all[object].index];
    const std::size_t room = kMaxStaticTileTriangles - tile.triangles.size();
    if (mesh.desc.triangles.size() <= detail::kBruteForceStaticTriangles) {
      // Whole, as every traversal tests such a mesh, but for the triangles
      // the cone misses.
      bool first = true;
      for (std::uint32_t t = 0; t < mesh.desc.triangles.size(); ++t) {
        const auto& v = mesh.desc.triangles[t];
        if (cone.misses(mesh.desc.positions[v[0]], mesh.desc.positions[v[1]], mesh.desc.positions[v[2]])) continue;
        if (tile.triangles.size() == kMaxStaticTileTriangles) return false;
        add_triangle(mesh, t, first, tile);
        first = false;
      }
    } else if (!gather_reached(mesh, box_test, grow, room, cone, tile)) {
      return false;
    }
    // A mesh counts as entered when the tile keeps some of its triangles.
    if (kMaxStaticTileTriangles - tile.triangles.size() < room) ++tile.meshes;
  }
  return true;
}

namespace {

// One group's rays, aligned for the eight-lane tests.
struct alignas(32) GroupRays {
  float o[3][kBlockLanes];
  float d[3][kBlockLanes];
  float t_min[kBlockLanes];
  float t_limit[kBlockLanes];  // closest hit: the best t so far (exclusive); any hit: t_max
  RayLanes8 lanes() const { return {o, d, t_min, t_limit}; }
};

// The rays the queries accept (traverse/ray_frames.h valid_rays).
std::uint32_t valid_lanes(const GroupRays& r) {
  const Vec3x8 o{Float8::load(r.o[0]), Float8::load(r.o[1]), Float8::load(r.o[2])};
  const Vec3x8 d{Float8::load(r.d[0]), Float8::load(r.d[1]), Float8::load(r.d[2])};
  return per_lane::valid_rays<Float8>(o, d, Float8::load(r.t_min), Float8::load(r.t_limit)).bits();
}

// The camera rays of one tile from `eye`: the triangles with their origin
// terms computed once for the whole tile.
class CameraBlocks {
 public:
  CameraBlocks(const std::vector<StaticTriangle>& triangles, const Vec3& eye) : triangles_(triangles) {
    thread_local std::vector<CommonOriginTriangle> prepared;
    prepared.clear();
    for (const StaticTriangle& tri : triangles) prepared.push_back(prepare_common_origin(eye, tri.p0, tri.p1, tri.p2));
    prepared_ = &prepared;
    for (int a = 0; a < 3; ++a) Float8(eye[a]).store(r_.o[a]);
    Float8(0.0f).store(r_.t_min);
  }

  // Block b's nearest hits into s; returns the hit lanes, counting the
  // tests of the lanes of `pixels` that are valid rays.
  std::uint32_t trace(TileScratch& s, std::size_t b, std::uint64_t objects, TraversalCounters& counters) {
    const std::size_t k0 = b * kBlockLanes;
    Float8::load(&s.dir_x[k0]).store(r_.d[0]);
    Float8::load(&s.dir_y[k0]).store(r_.d[1]);
    Float8::load(&s.dir_z[k0]).store(r_.d[2]);
    Float8(kInf).store(r_.t_limit);
    const std::uint32_t live = valid_lanes(r_) & s.block_pixels[b];
    alignas(32) float best_u[kBlockLanes] = {}, best_v[kBlockLanes] = {};
    // Per lane the index of its nearest triangle so far, as a float (exact:
    // far fewer than 2^24 triangles), chosen by the hit mask like t, u, v.
    Float8 best_index(0.0f);
    std::uint32_t hits = 0;
    // The last triangle hit, and its lanes: when those are all of the hit
    // lanes, every hit lane ended on it (a ground block, mostly).
    std::size_t last = 0;
    std::uint32_t last_lanes = 0;
    if (live != 0) {
      const std::uint64_t lanes = static_cast<std::uint64_t>(std::popcount(live));
      counters.object_visits += objects * lanes;
      counters.triangle_tests += triangles_.size() * lanes;
      for (std::size_t i = 0; i < triangles_.size(); ++i) {
        alignas(32) float t[kBlockLanes], u[kBlockLanes], v[kBlockLanes];
        const std::uint32_t hit =
            intersect_triangle_fast8_common_origin(r_.lanes(), live, (*prepared_)[i], t, u, v);
        if (hit == 0 || triangles_[i].zero_area) continue;
        const Mask8 m = Mask8::from_bits(hit);
        select(m, Float8::load(t), Float8::load(r_.t_limit)).store(r_.t_limit);
        select(m, Float8::load(u), Float8::load(best_u)).store(best_u);
        select(m, Float8::load(v), Float8::load(best_v)).store(best_v);
        best_index = select(m, Float8(static_cast<float>(i)), best_index);
        last = i;
        last_lanes = hit;
        hits |= hit;
      }
    }
    Float8::load(r_.t_limit).store(&s.t[k0]);
    Float8::load(best_u).store(&s.u[k0]);
    Float8::load(best_v).store(&s.v[k0]);
    if (hits != 0 && last_lanes == hits) {
      const std::uint32_t triangle = triangles_[last].triangle, instance = triangles_[last].instance;
      for (int lane = 0; lane < kBlockLanes; ++lane) {
        const bool hit = (hits >> lane & 1u) != 0;
        s.triangle[k0 + static_cast<std::size_t>(lane)] = hit ? triangle : kInvalidId;
        s.instance[k0 + static_cast<std::size_t>(lane)] = hit ? instance : kInvalidId;
      }
      return hits;
    }
    alignas(32) std::int32_t best[kBlockLanes];
    store_truncated(best_index, best);
    for (int lane = 0; lane < kBlockLanes; ++lane) {
      const std::size_t k = k0 + static_cast<std::size_t>(lane);
      const bool hit = (hits >> lane & 1u) != 0;
      s.triangle[k] = hit ? triangles_[static_cast<std::size_t>(best[lane])].triangle : kInvalidId;
      s.instance[k] = hit ? triangles_[static_cast<std::size_t>(best[lane])].instance : kInvalidId;
    }
    return hits;
  }

 private:
  const std::vector<StaticTriangle>& triangles_;
  const std::vector<CommonOriginTriangle>* prepared_ = nullptr;
  GroupRays r_;
};

// The shadow rays of one tile. Rays from one point (a point light's:
// s.shadows_from_point) test the triangles with their origin terms
// computed once for the whole tile.
class ShadowBlocks {
 public:
  ShadowBlocks(const std::vector<StaticTriangle>& triangles, const TileScratch& s) : triangles_(triangles) {
    thread_local std::vector<CommonOriginTriangle> prepared;
    prepared.clear();
    if (s.shadows_from_point) {
      for (const StaticTriangle& tri : triangles) {
        prepared.push_back(prepare_common_origin(s.shadow_origin, tri.p0, tri.p1, tri.p2));
      }
    }
    prepared_ = &prepared;
  }

  // The blocked lanes of the `n` shadow rays from i (the arrays hold a
  // spare group past the last ray: tile_scratch.h).
  std::uint32_t blocked(const TileScratch& s, std::size_t i, std::size_t n, TraversalCounters& counters) const {
    GroupRays r;
    Float8(0.0f).store(r.t_min);
    Float8::load(&s.so_x[i]).store(r.o[0]);
    Float8::load(&s.so_y[i]).store(r.o[1]);
    Float8::load(&s.so_z[i]).store(r.o[2]);
    Float8::load(&s.sd_x[i]).store(r.d[0]);
    Float8::load(&s.sd_y[i]).store(r.d[1]);
    Float8::load(&s.sd_z[i]).store(r.d[2]);
    Float8::load(&s.s_tmax[i]).store(r.t_limit);
    std::uint32_t live = valid_lanes(r) & ((1u << n) - 1u);
    std::uint32_t blocked = 0;
    const bool common = !prepared_->empty();
    for (std::size_t t = 0; t < triangles_.size() && live != 0; ++t) {
      const std::uint64_t lanes = static_cast<std::uint64_t>(std::popcount(live));
      const StaticTriangle& tri = triangles_[t];
      if (tri.first) counters.object_visits += lanes;
      counters.triangle_tests += lanes;
      alignas(32) float th[kBlockLanes], u[kBlockLanes], v[kBlockLanes];
      const std::uint32_t hit =
          common ? intersect_triangle_fast8_common_origin(r.lanes(), live, (*prepared_)[t], th, u, v)
                 : intersect_triangle_fast8(r.lanes(), live, tri.p0, tri.p1, tri.p2, th, u, v);
      if (hit == 0 || tri.zero_area) continue;
      blocked |= hit;
      live &= ~hit;
    }
    return blocked;
  }

 private:
  const std::vector<StaticTriangle>& triangles_;
  const std::vector<CommonOriginTriangle>* prepared_ = nullptr;
};


}  // namespace

void intersect_static_tile(const StaticTile& tile, const Vec3& eye, TileScratch& s, TraversalCounters& counters) {
  CameraBlocks blocks(tile.triangles, eye);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    s.block_hits[b] = static_cast<std::uint8_t>(blocks.trace(s, b, tile.meshes, counters));
  }
}

std::uint64_t occluded_static_tile(const StaticTile& tile, int l, TileScratch& s, TraversalCounters& counters) {
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  std::uint64_t blocked_count = 0;
  const ShadowBlocks blocks(tile.triangles, s);
  for (std::size_t i = 0; i < s.shadow_count; i += kBlockLanes) {
    const std::size_t n = std::min<std::size_t>(kBlockLanes, s.shadow_count - i);
    for (std::uint32_t m = blocks.blocked(s, i, n, counters); m != 0; m &= m - 1) {
      s.lit[s.shadow_pixel[i + static_cast<std::size_t>(std::countr_zero(m))]] &= dark;
      ++blocked_count;
    }
  }
  return blocked_count;
}

}  // namespace sinew::rt
