// Per-frame linear blend skinning into world space, with the escape check
// fused in (paper section 3; docs/DESIGN.md section 4, "Escaped triangles go to the fallback").
//
// The kernel reads the rest mesh once and writes world positions (and,
// when asked, normals: blended with the same matrices and not renormalised,
// the shader normalises). When an escape check is given, each vertex is also
// transformed into the frame of every bone it has a check for and compared
// with its fuzzy box grown by that bone's tolerance; failures are flagged per
// check and counted. Work is split over vertices in fixed chunks, so results
// do not depend on the thread count. An AVX2+FMA path (8 vertices at a time)
// and a scalar path give the same results to within float rounding; kAuto
// picks AVX2 when the build and the CPU have it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/skinning/packed_influences.h"
#include "raytrace/skinning/rigid_checks.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew {
class JobSystem;
}

namespace sinew::rt {

// Skins one rest position with `bones` (scalar reference for tests and the bake).
inline Vec3 skin_point(const SkinnedMesh& mesh, std::size_t v, std::span<const Affine3> bones) {
  const auto& joints = mesh.joints[v];
  const auto& weights = mesh.weights[v];
  const Vec3& p = mesh.positions[v];
  Vec3 out(0.0f);
  for (int k = 0; k < kMaxInfluences; ++k) {
    const float w = weights[static_cast<std::size_t>(k)];
    if (w == 0.0f) continue;
    out += w * bones[joints[static_cast<std::size_t>(k)]].transform_point(p);
  }
  return out;
}

struct EscapeCheckInput {
  std::span<const std::uint32_t> vertex_check_begin;  // from FuzzyCharacterView
  std::span<const VertexCheck> vertex_checks;
  // Per bone: world -> bone frame (the inverse skinning matrix). A bone whose
  // inverse is not finite (zero scale) fails every check against it.
  std::span<const Affine3> bone_from_world;
  // Per bone: how far (bone-frame units) a vertex may lie outside its box
  // before it counts as escaped; covers the float rounding of skinning and of
  // the inverse transform far from the origin.
  std::span<const float> tolerance;
  // Optional (empty: not computed), chunk_count(vertices) x
  // bone_from_world.size() boxes, row-major: per chunk of
  // kSkinningChunkVertices vertices and per bone, the box of the chunk's
  // skinned positions of the vertices with a check against that bone.
  // Merged in chunk order they are each bone's world bounds of its skinned
  // triangles, gathered while the check reads the checks anyway (a pass of
  // of its own would read every check again).
  std::span<Aabb> chunk_bone_boxes;
  // Optional (empty: every check against its own box): per bone, the boxes
  // its checks are held to instead, indexed by check_rank (the bone's
  // pose-space cluster's, FuzzyCharacterView::cluster_boxes), or null for
  // the checks' own. check_rank has one entry per check when given; a
  // check ranked kSharedCheckBox keeps its own box.
  std::span<const Aabb* const> bone_boxes;
  std::span<const std::uint32_t> check_rank;
  // Optional (empty: every check computed): per block of eight vertices the
  // bone its checks are rigid in, or kNotRigid (find_rigid_check_blocks,
  // rigid_checks.h). Such a block's checks pass without being computed
  // while its positions are finite and its bone's world -> bone transform
  // and tolerance are (the answer the computed check gives wherever the
  // tolerance bounds the rounding, as it is made to).
  std::span<const std::uint16_t> rigid_blocks;
};

// The work is split over vertices in chunks of this many (a multiple of
// the AVX2 width, so only the last chunk has a scalar tail).
inline constexpr std::size_t kSkinningChunkVertices = 1024;
inline std::size_t skinning_chunk_count(std::size_t vertices) {
  return (vertices + kSkinningChunkVertices - 1) / kSkinningChunkVertices;
}

enum class SkinningPath : std::uint8_t { kAuto, kScalar, kAvx2 };

struct SkinningTargets {
  std::span<Vec3> positions;  // vertex_count, required
  std::span<Vec3> normals;    // vertex_count, or empty to skip normals
  std::span<std::uint8_t> escaped;  // vertex_checks.size() when an escape check is given: 1 = escaped
};

struct SkinningResult {
  std::size_t escaped_checks = 0;
  SkinningPath path_used = SkinningPath::kScalar;
};

// `bones` are the skinning matrices (bind pose -> world) indexed by the mesh's
// joint indices; the caller guarantees every joint index is < bones.size()
// (the bake and the loaders validate it). `jobs` may be null (single thread).
// `influences` is pack_influences(mesh), packed once per mesh; the overload
// without it packs them on every call.
SkinningResult skin_vertices(const SkinnedMesh& mesh, const PackedInfluences& influences,
                             std::span<const Affine3> bones, const SkinningTargets& targets,
                             const EscapeCheckInput* escape, JobSystem* jobs,
                             SkinningPath path = SkinningPath::kAuto);
SkinningResult skin_vertices(const SkinnedMesh& mesh, std::span<const Affine3> bones,
                             const SkinningTargets& targets, const EscapeCheckInput* escape,
                             JobSystem* jobs, SkinningPath path = SkinningPath::kAuto);

// The escape check alone over positions already skinned (as skin_vertices
// runs it: the same bits, escaped flags and chunk_bone_boxes): for a frame
// whose bones changed the boxes they are held to. Returns the escaped checks.
std::size_t check_escapes(const EscapeCheckInput& escape, std::span<const Vec3> positions,
                          std::span<std::uint8_t> escaped, JobSystem* jobs);

// Whether this build and CPU can run SkinningPath::kAvx2.
bool avx2_skinning_available();

}  // namespace sinew::rt
