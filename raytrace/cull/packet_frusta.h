// PacketFrusta: the one culler a packet's walk asks (cull/frustum_culler.h),
// over the two kinds of frusta for rays from one apex: the camera's grid
// (GridFrusta), or each group's own frustum or slab (GroupFrusta), built when
// a leaf first needs them, eight groups at a time. The walk never asks which
// kind it has.
#pragma once

#include <algorithm>
#include <cstdint>

#include "raytrace/cull/frustum_culler.h"
#include "raytrace/cull/grid_frusta.h"
#include "raytrace/cull/group_frusta.h"
#include "runtime/math/aabb.h"

namespace sinew::rt {

template <int kGroups>
class PacketFrusta {
 public:
  // A camera packet's pixel grid (LargePacketRays::grid_columns and basis);
  // columns 0: none.
  struct Grid {
    int columns = 0;
    Vec3 forward{0.0f}, right{0.0f}, up{0.0f};
  };

  // Nothing culled until start() finds rays it can bound.
  void off() {
    on_ = false;
    built_ = 0;
    grid_.reset();
  }
  bool on() const { return on_; }

  // For `groups` groups of rays from `apex`, t >= 0 (or with a radius,
  // segments from within it of the apex to apex + reach directions; see
  // GroupFrusta::reset): the grid's planes when the packet has a grid that
  // bounds its rays, else group frusta built as leaves need them (`slabs`:
  // each group's slab in the packet's basis, for shadow packets).
  // directions(g): group g's directions [3][8]; lanes(g): its live lanes.
  template <class Directions, class Lanes>
  void start(const Vec3& apex, float radius, int groups, const Grid& grid, bool slabs, Directions&& directions,
             Lanes&& lanes) {
    off();
    on_ = true;
    if (grid.columns > 0 && radius == 0.0f &&
        grid_.build(apex, grid.forward, grid.right, grid.up, groups, grid.columns, directions, lanes)) {
      return;
    }
    frusta_.reset(apex, groups, radius);
    slabs_ = slabs;
    frusta_.use_slabs(slabs_);
  }

  // Builds the frusta of `groups` and of every other group of `alive` not
  // built yet: together, eight at a time, they cost about what one does.
  // reach(g, out): group g's lanes' t_max, for rays that end (shadow rays;
  // kFar), giving each frustum a far plane.
  template <bool kFar, class Directions, class Lanes, class Reach>
  void ensure(std::uint64_t groups, std::uint64_t alive, Directions&& directions, Lanes&& lanes, Reach&& reach) {
    if (grid_.on() || (groups & ~built_) == 0) return;
    const std::uint64_t unbuilt = alive & ~built_;
    // The packet's own frustum over every group built so far.
    const std::uint64_t built = built_ | unbuilt;
    frusta_.template set_bound<kFar>(built, 1.0f, directions, lanes, reach);
    // The groups' own frusta only where the packet's slabs are off.
    if (!slabs_ || (built & ~frusta_.slab_groups()) != 0) {
      frusta_.template set_groups<kFar>(unbuilt, 1.0f, directions, lanes, reach);
    }
    built_ = built;
  }

  // Whether any plane was built: rays spread too wide (or segments whose
  // ends lie too near their apex) leave none.
  bool culls() const { return grid_.on() || frusta_.any_plane(); }

  // The groups of `groups` whose frustum may reach the box.
  std::uint64_t box_reached(const Aabb& box, std::uint64_t groups) const {
    return grid_.on() ? grid_.box_reached(box, groups) : frusta_.box_reached(box, groups);
  }

  // The groups of `groups` whose frustum may reach the triangle.
  std::uint64_t reached(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint64_t groups) const {
    return grid_.on() ? grid_.reached(p0, p1, p2, groups) : frusta_.reached(p0, p1, p2, groups);
  }

  // Per triangle i of `t` in `lanes`, the groups of `groups` whose frustum
  // may reach it.
  void reached8(const TriangleLanes8& t, std::uint32_t lanes, std::uint64_t groups, std::uint64_t (&out)[8]) const {
    if (grid_.on()) {
      grid_.reached8(t, lanes, groups, out);
    } else {
      frusta_.reached8(t, lanes, groups, out);
    }
  }

 private:
  GroupFrusta<kGroups> frusta_;
  GridFrusta grid_;               // on: a camera packet's planes, used instead of frusta_
  bool on_ = false;
  bool slabs_ = false;            // frusta_ tests the groups' slabs in the packet's basis
  std::uint64_t built_ = 0;       // the groups whose frustum frusta_ holds
};

static_assert(FrustumCuller<GroupFrusta<64>>);
static_assert(FrustumCuller<GridFrusta>);
static_assert(FrustumCuller<PacketFrusta<64>>);

}  // namespace sinew::rt
