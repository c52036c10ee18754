// InstanceFrame: everything one character instance computes per frame, and
// the per-frame steps that compute it. Core data (mesh, fuzzy trees) is
// shared; an instance owns only this.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/accel/kd_tree.h"
#include "raytrace/accel/top_level.h"
#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/scene/leaf_boxes.h"
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
  // Queries skip the instance when (mask & ray mask) == 0 (Scene::set_mask).
  std::uint32_t mask = kAllMaskBits;
  // Culled this frame (FrameOptions::visibility): no ray of the frame can
  // reach it, so nothing below but `skinning` and `bounds` is current and
  // the top level leaves it out.
  bool culled = false;
  // This frame's conservative world bounds (instance_bounds), computed when
  // the frame is culled by visibility; empty otherwise.
  Aabb bounds;

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

  // Pose-space clusters (FuzzyCharacterView::clusters): per bone the
  // cluster whose tree and boxes it uses this frame (an index into
  // clusters), or -1 for its full tree; and the boxes its checks are held to
  // (the cluster's, null for the checks' own).
  std::vector<std::int32_t> bone_cluster;
  std::vector<const Aabb*> bone_check_boxes;
  std::size_t cluster_bones = 0;   // bones on a cluster's tree this frame
  std::size_t cluster_misses = 0;  // bones whose cluster a vertex left: back on their full tree

  // The tree bone b is traversed with this frame (a kd-tree or a BVH, as
  // fuzzy.tree_kind says).
  const BoneTree& bone_tree(const FuzzyCharacterView& fuzzy, std::uint32_t bone) const {
    const std::int32_t q = bone < bone_cluster.size() ? bone_cluster[bone] : -1;
    return q < 0 ? fuzzy.bone_trees[bone] : fuzzy.clusters[static_cast<std::size_t>(q)].tree;
  }

  // The current world boxes of the bone trees' leaves, filled as packets
  // reach them (leaf_boxes.h); Scene::prepare_frame starts each frame.
  LeafBoxCache leaf_boxes;

  std::vector<std::uint32_t> escaped_triangles;  // triangle ids routed through the fallback
  KdTree fallback;  // world-space tree; items index escaped_triangles
  std::size_t escaped_checks = 0;
  std::size_t singular_bones = 0;
};

// What the per-frame steps need only while one instance is prepared:
// Scene::prepare_frame prepares one instance at a time and keeps one of
// these, so its size follows the largest character, not the crowd.
struct FrameScratch {
  std::vector<std::uint8_t> escaped;  // per vertex check: 1 = outside its fuzzy box
  // Exact bone boxes: per skinning chunk and bone, the box of its checked
  // vertices (EscapeCheckInput::chunk_bone_boxes), merged by compute_bone_boxes.
  std::vector<Aabb> chunk_bone_boxes;
};

// What bounds a character's skinned vertices in any pose: per bone, the box
// of the rest positions of the vertices it weights, and the range of the
// vertices' weight sums (1 for normalised weights).
struct InfluenceBounds {
  std::vector<Aabb> bone_rest_boxes;
  float weight_sum_lo = 1.0f;
  float weight_sum_hi = 1.0f;
};
InfluenceBounds influence_bounds(const SkinnedMesh& mesh, std::size_t bone_count);

// A box holding every vertex of the instance skinned by `skinning`, in any
// pose, escaped or not: a skinned vertex is sum_j w_j S_j p with weights >= 0,
// so it lies in its weight sum times the box of the S_j-carried rest boxes
// of the bones weighting it; grown for the rounding of skinning. One box
// transform per bone, no vertex read.
Aabb instance_bounds(std::span<const Affine3> skinning, const InfluenceBounds& bounds);

// Relative slack for float rounding in bone-frame computations: a few units
// in the last place of the magnitudes involved.
inline constexpr float kFrameRelativeSlack = 8.0f * 0x1.0p-24f;

// Inverses, usable flags and escape tolerances from `skinning`.
void update_bone_frames(InstanceFrame& frame, const FuzzyCharacterView& fuzzy);

// Picks each bone's pose-space cluster, the one whose centre is nearest its
// feature this frame (raytrace/fuzzy/pose_clusters.h); none (-1) for every
// bone when `use` is false or the character has no clusters.
void choose_bone_clusters(InstanceFrame& frame, const FuzzyCharacterView& fuzzy, bool use);

// Skins positions (and normals) and runs the escape check; with
// `exact_boxes`, it also gathers the bone boxes compute_bone_boxes merges.
// `influences` is pack_influences(mesh), `rigid_blocks` the character's
// find_rigid_check_blocks (rigid_checks.h; empty: every check computed).
void skin_instance(InstanceFrame& frame, FrameScratch& scratch, const SkinnedMesh& mesh,
                   const PackedInfluences& influences, const FuzzyCharacterView& fuzzy,
                   std::span<const std::uint16_t> rigid_blocks, bool normals, bool exact_boxes, SkinningPath path,
                   JobSystem& jobs);

// After skin_instance: a bone whose cluster a vertex left goes back to its
// full tree, and the escape check runs again (positions as they are)
// against the full boxes of those bones.
void settle_bone_clusters(InstanceFrame& frame, FrameScratch& scratch, const FuzzyCharacterView& fuzzy,
                          std::span<const std::uint16_t> rigid_blocks, JobSystem& jobs);

// Per bone world boxes: exact (union of the bone's skinned vertices, from
// the boxes skin_instance gathered with exact_boxes) or cheap (the fuzzy
// root box, grown by the tolerance, carried by the bone matrix).
void compute_bone_boxes(InstanceFrame& frame, const FrameScratch& scratch, const FuzzyCharacterView& fuzzy,
                        bool exact);

// Collects triangles with an escaped corner (or on a singular bone) and
// builds the world-space fallback tree over them.
Status build_fallback(InstanceFrame& frame, const FrameScratch& scratch, const SkinnedMesh& mesh,
                      const FuzzyCharacterView& fuzzy, const KdBuildOptions& kd);

}  // namespace sinew::rt
