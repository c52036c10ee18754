#include "raytrace/cull/static_tiles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "raytrace/cull/interval_walk.h"
#include "raytrace/traverse/traversal_shared.h"

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
bool gather_reached(const Scene::StaticMesh& mesh, const IntervalBound& test, float grow, std::size_t room,
                    const TileCone& cone, StaticTile& tile) {
  thread_local std::vector<std::uint32_t> reached;
  reached.clear();
  bool fits = true;
  for_each_reached_leaf(mesh.tree.view(), test, grow, [&](std::span<const std::uint32_t> items) {
    for (std::size_t i = 0; i < items.size() && fits; ++i) {
      const std::uint32_t t = items[i];
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
  const IntervalBound box_test = bound.test();
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

}  // namespace sinew::rt
