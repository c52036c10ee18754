// The brute-force reference of `sinew-bench queries`: each instance of one
// character skinned from the tick's skinning matrices, and a ray's nearest
// hit found by testing it against every triangle of every instance (the
// watertight test, no acceleration structure of Sinew's or Embree's).
//
// The skinning is Sinew's kernel (rt::skin_vertices), the one both
// contenders' triangles come from, so the reference's triangles are theirs
// to the bit: what is checked is which triangle each ray hits, not how two
// skinnings round. (With another rounding, a ray across a small triangle's
// edge far from the origin lands on either side of it by more than the
// comparison's edge tolerance.)
//
// One shortcut, which changes no answer: an instance whose box (of its
// skinned positions, grown by a margin that absorbs the slab test's
// rounding) the ray misses holds no triangle the ray can hit, so its
// triangles are skipped.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/math/aabb.h"
#include "runtime/math/affine.h"
#include "runtime/math/ray.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::bench {

class CrowdReference {
 public:
  // `mesh` must outlive the reference. `ids`: the id each instance's hits
  // report (the World's InstanceId), one per instance.
  CrowdReference(const SkinnedMesh& mesh, std::span<const std::uint32_t> ids)
      : mesh_(&mesh),
        influences_(rt::pack_influences(mesh)),
        ids_(ids.begin(), ids.end()),
        positions_(ids.size()),
        boxes_(ids.size()) {
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      if (slot_of_id_.size() <= ids_[i]) slot_of_id_.resize(ids_[i] + 1, kNoSlot);
      slot_of_id_[ids_[i]] = static_cast<std::uint32_t>(i);
    }
  }

  // Instance `slot`'s positions for this tick, skinned with `bones`
  // (bind pose -> world, one per joint of the mesh).
  void pose(std::size_t slot, std::span<const Affine3> bones) {
    std::vector<Vec3>& out = positions_[slot];
    out.resize(mesh_->vertex_count());
    rt::SkinningTargets targets;
    targets.positions = out;
    rt::skin_vertices(*mesh_, influences_, bones, targets, nullptr, nullptr);
    Aabb box;
    for (const Vec3& p : out) box.extend(p);
    const Vec3 margin = 1e-3f * (box.upper - box.lower) + Vec3(1e-5f);
    boxes_[slot] = {box.lower - margin, box.upper + margin};
  }

  // The nearest hit of `ray` over every triangle of every instance; ties
  // keep the first in instance, then triangle, order.
  Hit nearest(const Ray& ray) const {
    Hit best;
    float t_max = ray.t_max;
    const rt::WatertightRay wr = rt::prepare_watertight(ray);
    for (std::size_t slot = 0; slot < positions_.size(); ++slot) {
      if (!reaches(boxes_[slot], ray, t_max)) continue;
      const std::vector<Vec3>& p = positions_[slot];
      for (std::uint32_t t = 0; t < mesh_->triangles.size(); ++t) {
        const auto& v = mesh_->triangles[t];
        rt::TriangleHit h;
        if (rt::intersect_triangle_watertight(wr, ray, t_max, p[v[0]], p[v[1]], p[v[2]], h)) {
          t_max = h.t;
          best = Hit{h.t, h.u, h.v, t, ids_[slot]};
        }
      }
    }
    return best;
  }

  // The corners of triangle `triangle` of the instance whose id is
  // `instance`, as posed this tick; empty for an id or triangle it does
  // not know (compare_nearest_hits' lookup).
  std::optional<std::array<Vec3, 3>> corners(std::uint32_t instance, std::uint32_t triangle) const {
    if (instance >= slot_of_id_.size() || slot_of_id_[instance] == kNoSlot) return std::nullopt;
    if (triangle >= mesh_->triangles.size()) return std::nullopt;
    const std::vector<Vec3>& p = positions_[slot_of_id_[instance]];
    const auto& v = mesh_->triangles[triangle];
    return std::array<Vec3, 3>{p[v[0]], p[v[1]], p[v[2]]};
  }

 private:
  static constexpr std::uint32_t kNoSlot = 0xFFFFFFFFu;

  // Whether the segment [t_min, t_max] of the ray meets the box (slab
  // test; an axis the ray runs parallel to keeps the origin's side).
  static bool reaches(const Aabb& box, const Ray& ray, float t_max) {
    float lo = ray.t_min, hi = t_max;
    for (int axis = 0; axis < 3; ++axis) {
      const float o = ray.origin[axis], d = ray.direction[axis];
      if (d == 0.0f) {
        if (o < box.lower[axis] || o > box.upper[axis]) return false;
        continue;
      }
      float t0 = (box.lower[axis] - o) / d, t1 = (box.upper[axis] - o) / d;
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0);
      hi = std::min(hi, t1);
      if (lo > hi) return false;
    }
    return true;
  }

  const SkinnedMesh* mesh_;
  rt::PackedInfluences influences_;
  std::vector<std::uint32_t> ids_;
  std::vector<std::uint32_t> slot_of_id_;
  std::vector<std::vector<Vec3>> positions_;
  std::vector<Aabb> boxes_;
};

}  // namespace sinew::bench
