// Static tiles: a tile whose rays can reach only a few triangles of static
// meshes (a ground, a floor, walls: most pixels of a frame, and their shadow
// rays). The triangles are gathered once from the tile's bound (small meshes
// whole, larger ones from the kd cells the bound reaches) less those the
// tile's cone misses, and the packet core tests every ray against them
// (traverse/large_packet.h, the StaticTile overloads). Culling is
// conservative, so each lane's nearest hit is the single ray's; at an exact
// tie in t the triangle gathered first wins (meshes in list order, triangles
// ascending). docs/RAYTRACE.md, "Static tiles" and "The tile's cone".
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/cull/frustum_culler.h"
#include "raytrace/cull/group_frusta.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"

namespace sinew::rt {

// At most this many triangles per tile take the direct tests: each costs
// every ray of the tile a share of an eight-lane test, against a tree walk
// per packet without it; 24 holds a box and the floor quads around it
// (docs/RAYTRACE.md, "Static tiles").
inline constexpr std::size_t kMaxStaticTileTriangles = 24;

struct StaticTriangle {
  Vec3 p0, p1, p2;
  std::uint32_t triangle;
  std::uint32_t instance;
  bool zero_area;  // never hit (the scalar test's last check, once per triangle)
  bool first;      // the first of its mesh: the rays enter a new object
};

// The triangles of one tile (per thread, reused).
struct StaticTile {
  std::vector<StaticTriangle> triangles;
  std::uint64_t meshes = 0;  // the static meshes they came from
};

// The cone from one apex (a camera's eye, a point light) spanned by the
// directions of a tile's extreme rays (its corner pixels', or those to the
// corners of the box its shadow rays end in), which holds every ray of the
// tile. A triangle it misses is never tested by the tile's rays: either all
// three corners lie beyond one of the cone's four planes
// (cull/group_frusta.h), or every corner ray lies beyond one of the
// triangle's edge planes through the apex. Both with a margin relative to
// the coordinate magnitudes (corners and apex) at the triangle, beyond which
// neither triangle test reports a hit off the triangle: the frusta's
// kFrustumMargin (2^-16) for the cone's planes, kConeEdgeMargin (2^-11, far
// wider) for the edge planes. The first drops floor triangles beside a tile,
// the second the half of a ground quad across its diagonal from the tile.
// The edge-plane cull's margin per unit of the coordinate magnitudes: wider
// than the frusta's, it still drops the far half of a ground quad.
inline constexpr double kConeEdgeMargin = 0x1.0p-11;

class TileCone {
 public:
  // No cone: every triangle may be hit.
  TileCone() = default;
  // From `count` (at most 8) directions; without a usable frustum (rays
  // spread over about 75 degrees) nothing is culled.
  TileCone(const Vec3& apex, const Vec3* directions, int count);
  bool misses(const Vec3& p0, const Vec3& p1, const Vec3& p2) const;

  // As every culler answers (cull/frustum_culler.h), for its one group
  // (bit 0): the box by the cone's planes, the triangle by misses().
  std::uint64_t box_reached(const Aabb& box, std::uint64_t groups) const {
    return on_ ? frustum_.box_reached(box, groups & 1u) : groups & 1u;
  }
  std::uint64_t reached(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint64_t groups) const {
    return misses(p0, p1, p2) ? 0u : groups & 1u;
  }

 private:
  bool on_ = false;
  Vec3 apex_{0.0f};
  std::array<Vec3, 8> directions_{};  // unit
  int count_ = 0;
  GroupFrusta<8> frustum_;
};

// Gathers into `tile` the triangles that some ray of `bound` may reach
// among `objects` (indices into scene.top_level().objects()), every box
// grown by `extra_grow` beyond the bound's slack bound as cull_objects
// grows it. Returns whether the direct tests apply: the fast triangle test,
// a non-empty list of static meshes only, and at most
// kMaxStaticTileTriangles triangles reached.
//
// Triangles `cone` misses are left out too, and do not count towards the
// limit (a tile on a ground quad keeps the half it sees).
bool gather_static_tile(const Scene& scene, TriangleTest test, const RayBound& bound, float extra_grow,
                        std::span<const std::uint32_t> objects, StaticTile& tile, const TileCone& cone = {});

static_assert(FrustumCuller<TileCone>);

}  // namespace sinew::rt
