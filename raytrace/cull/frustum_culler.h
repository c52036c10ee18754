// FrustumCuller: the one interface of the cullers of rays from one apex
// (camera rays, a point light's shadow rays). A culler holds the frusta of a
// set of ray groups (bit g of a mask: group g) and answers, for a box or a
// triangle, which of the asked groups may reach it; a group is dropped only
// where none of its rays can hit the shape by either triangle test
// (kFrustumMargin). GroupFrusta (group_frusta.h) and GridFrusta
// (grid_frusta.h) implement it; PacketFrusta (packet_frusta.h) is whichever a
// packet has, and TileCone (static_tiles.h) a whole tile's rays.
#pragma once

#include <concepts>
#include <cstdint>

#include "runtime/math/aabb.h"
#include "runtime/math/types.h"

namespace sinew::rt {

template <class C>
concept FrustumCuller = requires(const C& culler, const Aabb& box, const Vec3& p, std::uint64_t groups) {
  // The groups of `groups` whose rays may reach the box.
  { culler.box_reached(box, groups) } -> std::same_as<std::uint64_t>;
  // The groups of `groups` whose rays may reach the triangle (p0, p1, p2).
  { culler.reached(p, p, p, groups) } -> std::same_as<std::uint64_t>;
};

}  // namespace sinew::rt
