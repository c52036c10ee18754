// Meshes: one primitive of one mesh node appended to the SkinnedMesh being
// built: vertices bound to their skin's joints (or rigidly to one joint),
// triangles in the spec's order, missing normals computed. Separate because
// it is the largest part and needs the skeleton only for joint indices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "editor/import/gltf_skeleton.h"

namespace sinew::editor::gltf_detail {

struct MeshBuilder {
  SkinnedMesh mesh;
  bool any_uvs = false;
};

Status add_primitive(const Ctx& c, const NodeGraph& g, const SkeletonPlan& plan,
                     const std::vector<int>& raw_to_sorted, std::size_t node_index,
                     std::size_t mesh_index, std::size_t prim_index, std::uint32_t material,
                     MeshBuilder& b);

}  // namespace sinew::editor::gltf_detail
