// The leaf triangle sources: what a tree's leaf items are, as world-space
// triangles, for each kind of top-level object. Every traversal width reads
// leaves through them, so an item means the same triangle everywhere.
//
//   bone tree   item = the character's triangle, corners skinned this frame
//   fallback    item = an index into the frame's escaped triangles
//   static mesh item = the mesh's triangle
#pragma once

#include <cstdint>

#include "raytrace/scene/scene.h"
#include "runtime/math/types.h"

namespace sinew::rt {

// A leaf item's triangle in world space, with the ids a hit reports.
struct LeafTriangle {
  const Vec3* p0;
  const Vec3* p1;
  const Vec3* p2;
  std::uint32_t triangle;
  std::uint32_t instance;
};

// A character instance's triangles (bone trees).
struct SkinnedTriangles {
  const SkinnedMesh& mesh;
  const InstanceFrame& frame;
  LeafTriangle operator()(std::uint32_t t) const {
    const auto& v = mesh.triangles[t];
    return {&frame.positions[v[0]], &frame.positions[v[1]], &frame.positions[v[2]], t, frame.instance_id};
  }
};

// A character instance's escaped triangles (its fallback tree).
struct EscapedTriangles {
  const SkinnedMesh& mesh;
  const InstanceFrame& frame;
  LeafTriangle operator()(std::uint32_t item) const {
    return SkinnedTriangles{mesh, frame}(frame.escaped_triangles[item]);
  }
};

// A static mesh's triangles.
struct StaticTriangles {
  const Scene::StaticMesh& mesh;
  LeafTriangle operator()(std::uint32_t t) const {
    const auto& v = mesh.desc.triangles[t];
    return {&mesh.desc.positions[v[0]], &mesh.desc.positions[v[1]], &mesh.desc.positions[v[2]], t,
            mesh.instance_id};
  }
};

}  // namespace sinew::rt
