// Coherent ray packets (paper section 4): eight rays traced together, so one
// node fetch and one box test serve all of them. An 8-ray packet is a large
// packet of one group (traverse/large_packet.h): the same walk, culling and
// triangle tests, so every packet width is one core. Each lane's nearest hit
// has the single-ray query's (traverse/traversal.h) t, u and v; between two
// triangles hit at exactly the same t the lane may keep the other one.
#pragma once

#include <cstdint>
#include <span>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/math/ray.h"

namespace sinew::rt {

inline constexpr int kPacketSize = 8;

// Structure of arrays, one ray per lane; lanes whose active bit is 0 are ignored.
struct alignas(32) RayPacket {
  float ox[kPacketSize], oy[kPacketSize], oz[kPacketSize];
  float dx[kPacketSize], dy[kPacketSize], dz[kPacketSize];
  float t_min[kPacketSize], t_max[kPacketSize];
  std::uint8_t active = 0xFF;

  Ray ray(int lane) const;
  void set(int lane, const Ray& ray);
};

// The top-level objects a packet may enter (indices into
// scene.top_level().objects()), in any order; a superset is fine, the
// packet culls them again. Without one, the packet's own bound culls the
// top level (cull/ray_bound.h).
struct ObjectFilter {
  std::span<const std::uint32_t> objects;
};

// Nearest hits for each active lane, intersect()'s per lane (see above);
// hits[i] of an inactive lane (or an invalid ray, as intersect() rejects)
// is a miss. Counters: rays, object visits and triangle tests per lane;
// node visits once per node the packet fetches.
void intersect_packet(const Scene& scene, const RayPacket& packet, TriangleTest test, Hit hits[kPacketSize],
                      TraversalCounters* counters = nullptr, const ObjectFilter* filter = nullptr);

// Occlusion per active lane as a bit mask (bit i = lane i occluded),
// occluded()'s per lane.
std::uint8_t occluded_packet(const Scene& scene, const RayPacket& packet, TriangleTest test,
                             TraversalCounters* counters = nullptr, const ObjectFilter* filter = nullptr);

// A packet's nearest hits written straight into structure-of-arrays
// storage (eight entries per group).
struct PacketHits {
  float* t;
  float* u;
  float* v;
  std::uint32_t* triangle;
  std::uint32_t* instance;
};

}  // namespace sinew::rt
