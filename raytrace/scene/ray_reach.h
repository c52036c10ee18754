// RayReach: which of a set of boxes a batch of ray segments can enter, one
// walk per ray through a kd-tree over the boxes, for the queries' lazy
// skinning (Scene::prepare_frame with FrameOptions::rays, docs/RAYTRACE.md,
// "Culling whole characters").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/accel/kd_tree.h"
#include "runtime/core/status.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"

namespace sinew::rt {

class RayReach {
 public:
  // reached[i] = 1 for every non-empty box i that some ray's segment
  // [t_min, t_max] enters once the box is grown by `margin` on every side
  // (0 for the others); a ray with a non-finite origin or direction reaches
  // every box. The walk and the box tests run in double, planes thickened by
  // the margin, so rounding never loses a box. Keeps its tree and scratch for
  // the next batch. Errors: a non-finite box (the kd build's).
  Status mark(std::span<const Ray> rays, std::span<const Aabb> boxes, double margin,
              std::vector<std::uint8_t>& reached);

 private:
  std::vector<Aabb> grown_;
  KdTree tree_;
};

}  // namespace sinew::rt
