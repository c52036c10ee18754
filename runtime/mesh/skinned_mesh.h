// SkinnedMesh: the immutable rest-pose mesh of a character, shared by all its
// instances. It lives in runtime/ because both animation/ (reference
// skinning, pose sampling) and raytrace/ (SIMD skinning, fuzzy boxes) read
// it, and raytrace/ must not depend on animation/.
//
// Layout is structure-of-arrays; influences are fixed at kMaxInfluences per
// vertex (unused slots have weight 0 and joint 0) so SIMD skinning needs no
// per-vertex branching. Triangle ids are the index into `triangles`, in the
// importer's documented order (docs/ANIMATION.md, "Importers").
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "runtime/image/texture.h"
#include "runtime/math/types.h"

namespace sinew {

inline constexpr int kMaxInfluences = 8;
inline constexpr std::uint32_t kNoTexture = 0xFFFFFFFFu;

struct SkinnedMesh {
  std::vector<Vec3> positions;  // bind pose, model space
  std::vector<Vec3> normals;    // bind pose, unit length (may be empty)
  std::vector<Vec2> uvs;        // may be empty
  std::vector<std::array<std::uint16_t, kMaxInfluences>> joints;
  std::vector<std::array<float, kMaxInfluences>> weights;  // each row sums to 1
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint32_t> triangle_material;  // per triangle, index into material_colors
  std::vector<Vec3> material_colors;             // linear RGB diffuse
  // Per material, its colour map in `textures` or kNoTexture (empty: none
  // has one). A textured material's albedo is its colour times the map's
  // RGB at the hit's uv.
  std::vector<std::uint32_t> material_texture;
  std::vector<Texture> textures;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
};

}  // namespace sinew
