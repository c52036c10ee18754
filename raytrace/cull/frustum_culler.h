// FrustumCuller: the one interface of every culler for rays from one apex
// (camera rays, a point light's shadow rays). A culler holds the frusta of
// a set of ray groups (bit g of a mask: group g) and answers, for a box or
// a triangle, which of the asked groups' rays may reach it. Answers are
// conservative: a group is dropped only where none of its rays can hit the
// shape by either triangle test (kFrustumMargin, group_frusta.h). The
// cullers:
//
//   GroupFrusta   (group_frusta.h)  each group's own planes, or its slab in
//                                   the packet's basis (shadow packets)
//   GridFrusta    (grid_frusta.h)   a plane pair per column and row of a
//                                   camera packet's pixel grid
//   PacketFrusta  (packet_frusta.h) whichever of the two a packet has
//   TileCone      (static_tiles.h)  one group: a whole tile's rays, which
//                                   also drops a triangle its rays pass
//                                   beside (the edge-plane test)
//
// The packet core's walk talks to PacketFrusta, the static-tile gather to
// TileCone; both ask the same two questions.
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
