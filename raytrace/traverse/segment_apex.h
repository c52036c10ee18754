// The apex of any-hit segments that start close together beside their
// lengths (an area light's samples, from the light to the hits), so a
// packet of them culls with frusta as rays from one point do
// (cull/group_frusta.h, GroupFrusta::reset and tilt_side;
// docs/RAYTRACE.md, "Soft shadows and ambient occlusion"). Private to
// traverse/.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "raytrace/cull/group_frusta.h"
#include "raytrace/traverse/packet_lanes.h"

namespace sinew::rt::packet_lanes {

// Segments whose origins spread over more than 1/kSegmentSpread of their
// nearest end's distance go without frusta: the tilted sides widen each
// group's frustum by about the radius near the apex, and past that the
// lanes' own clips to cells cull more.
inline constexpr float kSegmentSpread = 16.0f;

// Each lane's far end relative to the apex: its frustum direction (reach 1).
struct SegmentEnds {
  alignas(32) float q[3][kLanes];
};

struct SegmentApex {
  Vec3 at{0.0f};        // the centre of the origins' box
  float radius = 0.0f;  // the farthest origin's distance from it, grown as a far plane is
};

// The apex of the live lanes (`live`, per group) of the groups of `alive`,
// every lane's segment running from its origin over t in [0, t_limit]
// (callers check t_min >= 0); each live lane's far end relative to it goes
// to `ends`. None for lanes without finite ends, or origins spread over
// more than 1/kSegmentSpread of the nearest end's distance.
template <std::size_t kGroups>
std::optional<SegmentApex> find_segment_apex(const std::array<Group, kGroups>& groups,
                                             const std::array<std::uint32_t, kGroups>& live, std::uint64_t alive,
                                             std::array<SegmentEnds, kGroups>& ends) {
  if (alive == 0) return std::nullopt;
  const Float8 inf(kInf);
  Vec3x8 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  bool finite = true;
  for_each_bit(alive, [&](int g) {
    const Group& gr = groups[static_cast<std::size_t>(g)];
    const Mask8 use = Mask8::from_bits(live[static_cast<std::size_t>(g)]);
    const Vec3x8 o = gr.origin();
    lo = {min(lo.x, select(use, o.x, inf)), min(lo.y, select(use, o.y, inf)), min(lo.z, select(use, o.z, inf))};
    hi = {max(hi.x, select(use, o.x, -inf)), max(hi.y, select(use, o.y, -inf)), max(hi.z, select(use, o.z, -inf))};
    finite = finite && (is_finite(Float8::load(gr.t_limit)) | !use).bits() == 0xFFu;
  });
  if (!finite) return std::nullopt;
  const Vec3 centre(0.5f * (reduce_min(lo.x) + reduce_max(hi.x)), 0.5f * (reduce_min(lo.y) + reduce_max(hi.y)),
                    0.5f * (reduce_min(lo.z) + reduce_max(hi.z)));
  const Vec3x8 at{Float8(centre.x), Float8(centre.y), Float8(centre.z)};
  Float8 spread(0.0f), nearest(kInf);
  for_each_bit(alive, [&](int g) {
    const Group& gr = groups[static_cast<std::size_t>(g)];
    const Mask8 use = Mask8::from_bits(live[static_cast<std::size_t>(g)]);
    const Vec3x8 w = gr.origin() - at;
    const Vec3x8 end = (gr.origin() + Float8::load(gr.t_limit) * gr.direction()) - at;
    SegmentEnds& e = ends[static_cast<std::size_t>(g)];
    end.x.store(e.q[0]);
    end.y.store(e.q[1]);
    end.z.store(e.q[2]);
    spread = max(spread, select(use, dot(w, w), Float8(0.0f)));
    nearest = min(nearest, select(use, dot(end, end), inf));
  });
  const float radius = far_offset(std::sqrt(reduce_max(spread)));
  if (!std::isfinite(radius) || !(kSegmentSpread * kSegmentSpread * radius * radius <= reduce_min(nearest))) {
    return std::nullopt;
  }
  return SegmentApex{centre, radius};
}

}  // namespace sinew::rt::packet_lanes
