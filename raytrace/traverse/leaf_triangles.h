// The leaf triangle sources: what a tree's leaf items are, as world-space
// triangles, for each kind of top-level object; and visit_object, which
// picks an object's tree and source. Every traversal width enters objects
// and reads leaves through them, so an object means the same walk and an
// item the same triangle everywhere.
//
//   bone tree   item = the character's triangle, corners skinned this frame
//   fallback    item = an index into the frame's escaped triangles
//   static mesh item = the mesh's triangle
#pragma once

#include <cstdint>

#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal_shared.h"
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

// Enters a top-level object whose box the query's rays reach: the tree
// its kind walks and the triangles its leaves name. The query `q` supplies
// the walks, each given `args` (its rays' state in the object):
//   q.bone_tree(frame, bone, character, SkinnedTriangles, args...)
//       the bone's fuzzy tree, walked with the rays in the bone's frame;
//   q.world_tree(tree, source, args...)
//       a world-space kd-tree (a static mesh's, the escape fallback's);
//   q.each_triangle(StaticTriangles, count, args...)
//       every triangle in order, no tree (detail::kBruteForceStaticTriangles).
template <class Query, class... Args>
auto visit_object(const Scene& scene, const TopLevelObject& object, Query& q, const Args&... args) {
  if (object.kind == TopLevelObject::Kind::kStatic) {
    const Scene::StaticMesh& mesh = scene.static_meshes()[object.index];
    const std::size_t count = mesh.desc.triangles.size();
    if (count <= detail::kBruteForceStaticTriangles) return q.each_triangle(StaticTriangles{mesh}, count, args...);
    return q.world_tree(mesh.tree.view(), StaticTriangles{mesh}, args...);
  }
  const InstanceFrame& frame = scene.instances()[object.index];
  const Scene::Character& character = scene.characters()[frame.character];
  if (object.kind == TopLevelObject::Kind::kBone) {
    return q.bone_tree(frame, object.bone, character, SkinnedTriangles{*character.mesh, frame}, args...);
  }
  return q.world_tree(frame.fallback.view(), EscapedTriangles{*character.mesh, frame}, args...);
}

}  // namespace sinew::rt
