#include "raytrace/traverse/packet_traversal.h"

#include <vector>

#include "raytrace/cull/ray_bound.h"
#include "raytrace/traverse/large_packet.h"

namespace sinew::rt {

Ray RayPacket::ray(int lane) const {
  Ray r;
  r.origin = Vec3(ox[lane], oy[lane], oz[lane]);
  r.direction = Vec3(dx[lane], dy[lane], dz[lane]);
  r.t_min = t_min[lane];
  r.t_max = t_max[lane];
  return r;
}

void RayPacket::set(int lane, const Ray& r) {
  ox[lane] = r.origin.x;
  oy[lane] = r.origin.y;
  oz[lane] = r.origin.z;
  dx[lane] = r.direction.x;
  dy[lane] = r.direction.y;
  dz[lane] = r.direction.z;
  t_min[lane] = r.t_min;
  t_max[lane] = r.t_max;
}

namespace {

// The packet as a large packet of one group.
LargePacketRays one_group(const RayPacket& packet) {
  LargePacketRays rays;
  rays.groups = 1;
  rays.o[0] = packet.ox;
  rays.o[1] = packet.oy;
  rays.o[2] = packet.oz;
  rays.d[0] = packet.dx;
  rays.d[1] = packet.dy;
  rays.d[2] = packet.dz;
  rays.t_min = packet.t_min;
  rays.t_max = packet.t_max;
  rays.active = &packet.active;
  return rays;
}

// The filter's objects, or the top level's objects the packet's bound may
// enter (into the calling thread's list).
std::span<const std::uint32_t> objects_for(const Scene& scene, const RayPacket& packet, const ObjectFilter* filter) {
  if (filter != nullptr) return filter->objects;
  thread_local std::vector<std::uint32_t> culled;
  culled.clear();
  const float* const o[3] = {packet.ox, packet.oy, packet.oz};
  const float* const d[3] = {packet.dx, packet.dy, packet.dz};
  RayBound bound;
  bound.add_lanes(o, d, packet.t_min, packet.t_max, packet.active);
  cull_objects(scene, bound, culled);
  return culled;
}

}  // namespace

void intersect_packet(const Scene& scene, const RayPacket& packet, TriangleTest test, Hit hits[kPacketSize],
                      TraversalCounters* counters, const ObjectFilter* filter) {
  alignas(32) float t[kPacketSize], u[kPacketSize], v[kPacketSize];
  alignas(32) std::uint32_t triangle[kPacketSize], instance[kPacketSize];
  intersect_large_packet(scene, one_group(packet), test, objects_for(scene, packet, filter),
                         PacketHits{t, u, v, triangle, instance}, counters);
  for (int lane = 0; lane < kPacketSize; ++lane) {
    hits[lane] = Hit{t[lane], u[lane], v[lane], triangle[lane], instance[lane]};
  }
}

std::uint8_t occluded_packet(const Scene& scene, const RayPacket& packet, TriangleTest test,
                             TraversalCounters* counters, const ObjectFilter* filter) {
  std::uint8_t blocked = 0;
  occluded_large_packet(scene, one_group(packet), test, objects_for(scene, packet, filter), &blocked, counters);
  return static_cast<std::uint8_t>(blocked & packet.active);
}

}  // namespace sinew::rt
