// One validation of mesh data for every path a mesh comes in by: a pack's
// MESH section (character/pack.cpp), the fuzzy bake's input
// (raytrace/bake/fuzzy_bake.cpp), a fuzzy view handed to
// Scene::add_character (raytrace/fuzzy/fuzzy_validate.cpp) and a static
// mesh (Scene::add_static_mesh). Every index is checked before anything
// reads through it and every float before it reaches a box or a ray, so a
// mesh that passes cannot make skinning, the bake or traversal read out of
// bounds or build NaN boxes.
//
// The first problem is returned (kInvalidData), naming the origin's file and
// the field with its indices: "cally.pack: MESH.joints[7][5] = 40: not below
// the joint count (37)".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "runtime/core/status.h"
#include "runtime/math/types.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew {

// Where the mesh came from, for the messages: the file (may be empty) and
// what goes before each field's name ("MESH." for a pack's section).
struct MeshOrigin {
  std::string_view file;
  std::string_view field_prefix;
};

// Positions finite; every triangle's corners below the position count;
// `triangle_material` empty or one per triangle, each below the material
// count (or 0 when there are no materials: the renderer's default colour);
// material colours finite.
Status check_triangle_mesh(const MeshOrigin& origin, std::span<const Vec3> positions,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           std::span<const std::uint32_t> triangle_material, std::span<const Vec3> material_colors);

// The same, and: one joint row and one weight row per position, normals and
// uvs empty or one per position and finite, every influence slot's joint
// below `joint_count` (SIMD skinning reads every slot, weighted or not) and
// its weight finite and >= 0.
// Also checks the material textures (check_material_textures).
Status check_skinned_mesh(const MeshOrigin& origin, const SkinnedMesh& mesh, std::size_t joint_count);

// `material_texture` empty or one per material, each kNoTexture or naming
// a texture, only where the mesh has uvs; every texture's levels
// (check_texture).
Status check_material_textures(const MeshOrigin& origin, const SkinnedMesh& mesh);

}  // namespace sinew
