// TopLevel: the per-frame kd-tree over every traceable object of the scene
// (paper section 4.2): each bone of each character instance (its world box),
// each static mesh, and each instance's fallback for escaped triangles. It
// holds tens to a few thousand boxes, so a full SAH rebuild per frame costs
// microseconds to a millisecond.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/accel/kd_tree.h"
#include "runtime/core/status.h"

namespace sinew::rt {

// Every mask bit set: what instances and rays have unless told otherwise.
inline constexpr std::uint32_t kAllMaskBits = 0xFFFFFFFFu;

struct TopLevelObject {
  enum class Kind : std::uint8_t { kBone, kStatic, kFallback };
  Kind kind = Kind::kBone;
  std::uint32_t index = 0;  // kBone/kFallback: instance index; kStatic: static mesh index
  std::uint32_t bone = 0;   // kBone only
  Aabb box;                 // world space
  // The instance's or static mesh's mask: a query with ray mask m skips the
  // object when (mask & m) == 0, before clipping the ray to its box.
  std::uint32_t mask = kAllMaskBits;
};

// Consecutive objects of one character instance (its bones and its
// fallback), or one static mesh: a box over the run lets a cull skip a whole
// character with one test (cull/ray_bound.h cull_objects).
struct ObjectRun {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  // Holds every coordinate of every member box, lower and upper corners
  // alike (so also of an inverted one, which the tree skips).
  Aabb box;
};

class TopLevel {
 public:
  // Rebuilds the tree over `objects` (taken over; the vector's capacity is
  // kept for the next frame by the caller swapping it back via take_objects).
  Status build(std::vector<TopLevelObject>&& objects, const KdBuildOptions& options);

  KdTreeView view() const { return tree_.view(); }
  std::span<const TopLevelObject> objects() const { return objects_; }
  // The objects in runs, in index order: every object in exactly one.
  std::span<const ObjectRun> runs() const { return runs_; }
  const Aabb& bounds() const { return tree_.bounds; }
  const KdTreeStats& stats() const { return tree_.stats; }

  // Sets the mask of every object of one instance (`static_mesh` false) or
  // one static mesh, in place: a mask changes without a rebuild.
  void set_mask(bool static_mesh, std::uint32_t index, std::uint32_t mask);

  // Hands back the object vector (cleared) so the next frame reuses its memory.
  std::vector<TopLevelObject> take_objects();

 private:
  std::vector<TopLevelObject> objects_;
  std::vector<Aabb> boxes_;
  std::vector<ObjectRun> runs_;
  KdTree tree_;
};

}  // namespace sinew::rt
