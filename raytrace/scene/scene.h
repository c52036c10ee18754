// Scene: what one frame traces: skinned character instances (sharing their
// characters' baked fuzzy data) and static meshes (a ground, a level), with
// a top-level kd-tree over them rebuilt every frame (paper section 4).
//
// Use: add characters and static meshes once, add instances, then every frame
// set each instance's bone matrices and call prepare_frame(), which skins,
// checks escapes, computes bone world boxes, builds the fallback for escaped
// triangles and rebuilds the top level. After that the scene is read-only and
// can be traced from many threads (traverse/traversal.h).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "raytrace/accel/kd_tree.h"
#include "raytrace/accel/top_level.h"
#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/scene/frame_state.h"
#include "raytrace/scene/ray_reach.h"
#include "raytrace/scene/visibility.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew {
class JobSystem;
class PhaseTimers;
}  // namespace sinew

namespace sinew::rt {

// How a bone's world box is found each frame (docs/RAYTRACE.md, "Per frame", step 3).
enum class BoneBoxMode : std::uint8_t {
  kExact,  // the union of the bone's skinned triangles: tight, costs a pass over them
  kCheap,  // the fuzzy root box carried by the bone matrix: free, looser
};

struct FrameOptions {
  BoneBoxMode bone_boxes = BoneBoxMode::kExact;
  // Route triangles that left their fuzzy boxes through a per-frame
  // world-space kd-tree so the image stays exact (docs/DESIGN.md section 4). Off:
  // escapes are still counted in FrameStats::escaped_checks (escaped_triangles
  // stays 0: nothing is routed), and may show as holes.
  bool fallback = true;
  bool normals = true;  // skin normals (shading needs them; depth-only passes do not)
  // Bones of characters baked with pose-space clusters use the tree of the
  // cluster nearest their pose (FuzzyBakeOptions::pose_clusters). Off: every
  // bone its full tree, as a pack without clusters.
  bool pose_clusters = true;
  SkinningPath skinning = SkinningPath::kAuto;
  KdBuildOptions top_level_kd{.traversal_cost = 1.0f, .intersection_cost = 4.0f,
                              .empty_bonus = 0.2f, .max_leaf_items = 1, .max_depth = 0};
  KdBuildOptions fallback_kd{};
  // The frame's camera and lights (render/frame_visibility.h makes them from
  // a renderer's camera and settings): instances no camera or shadow ray can
  // reach are culled, neither skinned nor checked nor in the top level, and
  // only their conservative bounds are computed (InstanceFrame::culled).
  // Unset: every instance is prepared, as queries from anywhere need.
  std::optional<FrameVisibility> visibility;
  // The rays a batch of queries will trace (the API's World::intersect and
  // occluded over a span), kept by the caller for the call: with them, only
  // the instances some ray's segment reaches are prepared, lazy skinning
  // (with a visibility as well, those either one reaches). Traversals of
  // other rays may then miss culled instances.
  std::span<const Ray> rays;
};

struct FrameStats {
  std::size_t escaped_checks = 0;     // (vertex, bone) pairs outside their fuzzy boxes
  std::size_t escaped_triangles = 0;  // triangles routed through the fallback (0 with it off)
  std::size_t singular_bones = 0;     // bones without a finite inverse (zero scale)
  std::size_t cluster_bones = 0;      // bones traversed with a pose-space cluster's tree
  std::size_t cluster_misses = 0;     // bones whose cluster a vertex left: back on their full tree
  std::uint32_t skinned_instances = 0;  // instances skinned and checked this frame
  std::uint32_t culled_instances = 0;   // instances no ray of FrameOptions::visibility or rays can reach
  std::uint32_t top_level_objects = 0;
  std::uint32_t top_level_nodes = 0;
  // Building the fallback trees over the escaped triangles (also the
  // "fallback" phase of the timers): what poses outside the baked pose
  // space cost before tracing (rays entering those trees are in the trace).
  // 0 when nothing escaped.
  double fallback_ms = 0.0;
};

// A static triangle mesh in world space (the arena's ground, obstacles).
struct StaticMeshDesc {
  std::vector<Vec3> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint32_t> triangle_material;  // per triangle, or empty (material 0)
  std::vector<Vec3> material_colors;             // linear RGB; empty = mid grey
};

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  // Registers a character's core data; both must outlive the scene. Checks
  // that the fuzzy data matches the mesh (counts, bone indices).
  Expected<std::uint32_t> add_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy);

  // An instance of a character, at the bind pose until set_bones. Instance
  // ids and static mesh ids share one numbering (Hit::instance_id).
  Expected<std::uint32_t> add_instance(std::uint32_t character);

  // Builds the static mesh's kd-tree once.
  Expected<std::uint32_t> add_static_mesh(StaticMeshDesc mesh, const KdBuildOptions& kd = {});

  // Removes an instance or a static mesh: its per-frame data and tree are
  // freed, the next prepare_frame leaves it out, and its id is never given
  // again (a stale id is refused, not taken for a newer object). Errors: an
  // id that was never given or is removed already.
  Status remove(std::uint32_t id);
  // Whether `id` names an instance or static mesh not removed.
  bool contains(std::uint32_t id) const;

  // The mask bits of an instance or static mesh (default kAllMaskBits):
  // queries with a ray mask skip it when (mask & ray mask) == 0
  // (traverse/traversal.h). Takes effect at once, also on the top level
  // already built. Errors: an id not contained.
  Status set_mask(std::uint32_t id, std::uint32_t mask);

  // This frame's skinning matrices of an instance (bind pose -> world), one
  // per bone of its character. Copied. Non-finite matrices are rejected.
  Status set_bones(std::uint32_t instance, std::span<const Affine3> skinning);

  // Skinning, escape check, bone boxes, fallback and top level, for the
  // instances FrameOptions::visibility does not cull. Phases are
  // recorded into `timers` when given: "skinning", "boxes", "fallback",
  // "top level".
  Expected<FrameStats> prepare_frame(const FrameOptions& options, JobSystem& jobs,
                                     PhaseTimers* timers = nullptr);

  // Read access for traversal and shading (valid after prepare_frame).
  struct Character {
    const SkinnedMesh* mesh = nullptr;
    FuzzyCharacterView fuzzy;
    PackedInfluences influences;  // the mesh's, packed once for the skinning
    std::vector<std::uint16_t> rigid_blocks;  // find_rigid_check_blocks, once for the escape check
    InfluenceBounds influence_bounds;  // once, for the instances' conservative bounds
  };
  struct StaticMesh {
    StaticMeshDesc desc;
    KdTree tree;
    std::uint32_t instance_id = 0;  // scene-wide id reported in hits
    bool live = true;               // false once removed (its mesh and tree freed)
    std::uint32_t mask = kAllMaskBits;  // set_mask
  };
  enum class ObjectKind : std::uint8_t { kCharacter, kStatic };
  struct ObjectSlot {
    ObjectKind kind = ObjectKind::kCharacter;
    std::uint32_t index = 0;  // into instances() or static_meshes()
  };

  std::span<const Character> characters() const { return characters_; }
  std::span<const InstanceFrame> instances() const { return instances_; }
  std::span<const StaticMesh> static_meshes() const { return statics_; }
  std::span<const ObjectSlot> object_slots() const { return slots_; }  // by instance id
  const TopLevel& top_level() const { return top_level_; }
  const Aabb& world_bounds() const { return top_level_.bounds(); }

 private:
  std::vector<Character> characters_;
  std::vector<InstanceFrame> instances_;
  std::vector<StaticMesh> statics_;
  std::vector<ObjectSlot> slots_;
  // Marks each live instance culled or not (FrameOptions::visibility, rays).
  Status cull_instances(const FrameOptions& options);

  TopLevel top_level_;
  FrameCull cull_;
  FrameScratch scratch_;  // one instance's escape flags and chunk boxes at a time
  RayReach reach_;
  std::vector<Aabb> reach_boxes_;       // per instance: its bounds (empty when removed)
  std::vector<std::uint8_t> reached_;  // per instance: a query ray reaches it
};

}  // namespace sinew::rt
