// Coherent ray packets (paper section 4): eight rays traced together through
// the top level and every tree, so one node fetch and one split decision
// serve all of them. Each lane's nearest hit has the single-ray query's
// (traverse/traversal.h) t, u and v: it reaches every cell with the same
// thick-plane slack and tests the same triangles with the same arithmetic.
// In kd-trees, without an object filter, each lane also walks the cells in
// the single ray's order, so results are bit for bit the same; in BVH bone
// trees and filtered object lists the order may differ, and between two
// triangles hit at exactly the same t the lane may keep the other one.
// Where the lanes disagree on which child is near (directions of opposite
// sign along a split axis) the subtree is walked once per sign.
//
// Built for AVX2+FMA (the default x86-64-v3 baseline) the split steps and
// box clips run eight lanes at once; other builds trace each lane with the
// single-ray query.
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
// scene.top_level().objects()), front to back, found by culling the
// packet's rays (cull/ray_bound.h). With a filter the top-level walk is
// skipped: the listed objects are entered in order, each lane over its
// whole ray up to its best hit so far. Culling is conservative, so results
// equal the walk's except where two objects are hit at exactly the same t
// (the earlier in the list wins).
struct ObjectFilter {
  std::span<const std::uint32_t> objects;
};

// Nearest hits for each active lane, intersect()'s per lane (see above);
// hits[i] of an inactive lane (or an invalid ray, as intersect() rejects)
// is a miss. Counters: rays, object visits and triangle tests per lane as
// intersect() counts them; node visits once per node the packet fetches.
void intersect_packet(const Scene& scene, const RayPacket& packet, TriangleTest test, Hit hits[kPacketSize],
                      TraversalCounters* counters = nullptr, const ObjectFilter* filter = nullptr);

// A packet's nearest hits written straight into structure-of-arrays
// storage (eight entries each).
struct PacketHits {
  float* t;
  float* u;
  float* v;
  std::uint32_t* triangle;
  std::uint32_t* instance;
};

// The short cut for packets that can only meet a few static triangles (a
// ground quad): when every object of `filter` is a static mesh small
// enough to test triangle by triangle (traverse/traversal_shared.h) and the
// test is kFast, tests them all against the packet in filter order and
// returns true with the nearest hits in `out` (misses: t = inf, ids
// kInvalidId), equal to intersect_packet's. Returns false, touching
// nothing, otherwise.
bool intersect_packet_small_statics(const Scene& scene, const RayPacket& packet, TriangleTest test,
                                    const ObjectFilter& filter, PacketHits out, TraversalCounters* counters);
// The same for occlusion: the blocked lanes as bits, or -1 when the short
// cut does not apply.
int occluded_packet_small_statics(const Scene& scene, const RayPacket& packet, TriangleTest test,
                                  const ObjectFilter& filter, TraversalCounters* counters);

// Occlusion per active lane as a bit mask (bit i = lane i occluded),
// occluded()'s per lane.
std::uint8_t occluded_packet(const Scene& scene, const RayPacket& packet, TriangleTest test,
                             TraversalCounters* counters = nullptr, const ObjectFilter* filter = nullptr);

}  // namespace sinew::rt
