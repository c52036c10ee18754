// InstanceFrame: everything one character instance computes per frame, and
// the per-frame steps that compute it. Core data (mesh, fuzzy trees) is
// shared; an instance owns only this.
#pragma once

#include <cstdint>
#include <vector>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/kdtree/kd_tree.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/core/status.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew {
class JobSystem;
}

namespace sinew::rt {

struct InstanceFrame {
  std::uint32_t character = 0;
  std::uint32_t instance_id = 0;  // scene-wide id reported in hits
  bool live = true;               // false once removed (Scene::remove): its data is freed

  std::vector<Affine3> skinning;         // per bone: bind pose -> world
  std::vector<Affine3> bone_from_world;  // per bone: the inverse (the bone frame)
  std::vector<std::uint8_t> bone_usable; // per bone: inverse finite (not a zero-scale bone)
  std::vector<float> tolerance;          // per bone: escape slack in bone-frame units
  // Per bone, the magnitudes that bound the rounding of carrying a ray into
  // the bone frame (read by every ray that enters the bone).
  struct BoneCarry {
    float linear_norm = 0.0f;            // infinity norm of bone_from_world's 3x3 part
    float translation_magnitude = 0.0f;  // max |translation| of bone_from_world
    float bounds_magnitude = 0.0f;       // max |coordinate| of the fuzzy root box
  };
  std::vector<BoneCarry> bone_carry;
  std::vector<Aabb> bone_world_boxes;    // per bone (empty for bones without triangles)

  std::vector<Vec3> positions;  // skinned, world space
  std::vector<Vec3> normals;    // skinned, world space, not unit length (empty when not asked)
  std::vector<std::uint8_t> escaped;  // per vertex check: 1 = outside its fuzzy box
  // Exact bone boxes: per skinning chunk and bone, the box of its checked
  // vertices (EscapeCheckInput::chunk_bone_boxes), merged by compute_bone_boxes.
  std::vector<Aabb> chunk_bone_boxes;

  std::vector<std::uint32_t> escaped_triangles;  // triangle ids routed through the fallback
  KdTree fallback;  // world-space tree; items index escaped_triangles
  std::size_t escaped_checks = 0;
  std::size_t singular_bones = 0;
};

// Relative slack for float rounding in bone-frame computations: a few units
// in the last place of the magnitudes involved.
inline constexpr float kFrameRelativeSlack = 8.0f * 0x1.0p-24f;

// Inverses, usable flags and escape tolerances from `skinning`.
void update_bone_frames(InstanceFrame& frame, const FuzzyCharacterView& fuzzy);

// Skins positions (and normals) and runs the escape check; with
// `exact_boxes`, it also gathers the bone boxes compute_bone_boxes merges.
// `influences` is pack_influences(mesh).
void skin_instance(InstanceFrame& frame, const SkinnedMesh& mesh, const PackedInfluences& influences,
                   const FuzzyCharacterView& fuzzy, bool normals, bool exact_boxes, SkinningPath path,
                   JobSystem& jobs);

// Per bone world boxes: exact (union of the bone's skinned vertices, from
// the boxes skin_instance gathered with exact_boxes) or cheap (the fuzzy
// root box, grown by the tolerance, carried by the bone matrix).
void compute_bone_boxes(InstanceFrame& frame, const FuzzyCharacterView& fuzzy, bool exact);

// Collects triangles with an escaped corner (or on a singular bone) and
// builds the world-space fallback tree over them.
Status build_fallback(InstanceFrame& frame, const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy,
                      const KdBuildOptions& kd);

}  // namespace sinew::rt
