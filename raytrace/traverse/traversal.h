// Single-ray queries against a prepared Scene (paper section 4.2):
// top-level kd-tree -> for each object the ray enters, either a bone's fuzzy
// kd-tree traversed with the ray carried into the bone's frame (origin and
// direction by the inverse skinning matrix, not renormalised, so t is the
// same in both frames) while the triangles are intersected in world space,
// or a world-space tree (static meshes, the fallback for escaped triangles).
//
// Robustness. Every tree is traversed with "thick" split planes and root
// boxes grown by a slack that bounds the float rounding of the frame change
// and of the escape check (scene/frame_state.h), so rounding never skips the
// cell a hit lies in; a cell is pruned only when its conservative entry t
// lies beyond the best hit so far. Triangles listed in several leaves are
// tested once per object (a small mailbox).
#pragma once

#include <cstdint>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "runtime/math/ray.h"

namespace sinew::rt {

// What a query did, summed over queries (every width counts alike: object
// visits and triangle tests per lane, node visits per node fetched).
struct TraversalCounters {
  std::uint64_t rays = 0;
  std::uint64_t node_visits = 0;      // inner and leaf nodes of every tree
  std::uint64_t object_visits = 0;    // bone / static / fallback objects entered
  std::uint64_t triangle_tests = 0;

  TraversalCounters& operator+=(const TraversalCounters& other) {
    rays += other.rays;
    node_visits += other.node_visits;
    object_visits += other.object_visits;
    triangle_tests += other.triangle_tests;
    return *this;
  }
  // The same work, counted for `n` rays (a query counts its work; its entry
  // point, the rays it was asked to trace).
  TraversalCounters for_rays(std::uint64_t n) const {
    TraversalCounters counted = *this;
    counted.rays = n;
    return counted;
  }
};

// The nearest hit with ray.t_min <= t < ray.t_max; Hit::valid() is false on a miss.
Hit intersect(const Scene& scene, const Ray& ray, TriangleTest test,
              TraversalCounters* counters = nullptr);

// Whether anything lies on the ray with ray.t_min <= t < ray.t_max (any hit).
bool occluded(const Scene& scene, const Ray& ray, TriangleTest test,
              TraversalCounters* counters = nullptr);

// The same with a ray mask: the top-level walk skips every object whose
// instance or static mesh has (mask & ray_mask) == 0 (Scene::set_mask)
// before it clips the ray to the object's box, so a skipped instance costs
// one test per top-level leaf that lists it. kAllMaskBits skips nothing.
Hit intersect(const Scene& scene, const Ray& ray, std::uint32_t ray_mask, TriangleTest test,
              TraversalCounters* counters = nullptr);
bool occluded(const Scene& scene, const Ray& ray, std::uint32_t ray_mask, TriangleTest test,
              TraversalCounters* counters = nullptr);

}  // namespace sinew::rt
