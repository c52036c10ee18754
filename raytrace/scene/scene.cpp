#include "raytrace/scene/scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "runtime/jobs/job_system.h"
#include "runtime/mesh/mesh_checks.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {
namespace {


// Trees built here are traversed with a fixed stack: cap their depth.
KdBuildOptions within_traversal_depth(KdBuildOptions options) {
  if (options.max_depth <= 0 || options.max_depth > kMaxTraversalDepth) {
    options.max_depth = options.max_depth <= 0 ? 0 : kMaxTraversalDepth;
  }
  return options;
}


float max_abs(const Aabb& box) {
  if (box.is_empty()) return 0.0f;
  return std::max({std::fabs(box.lower.x), std::fabs(box.lower.y), std::fabs(box.lower.z), std::fabs(box.upper.x),
                   std::fabs(box.upper.y), std::fabs(box.upper.z)});
}

}  // namespace

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Expected<std::uint32_t> Scene::add_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  SINEW_RETURN_IF_ERROR(validate_fuzzy_character(mesh, fuzzy));
  PackedInfluences influences = pack_influences(mesh);
  std::vector<std::uint16_t> rigid =
      find_rigid_check_blocks(mesh, influences, fuzzy.vertex_check_begin, fuzzy.vertex_checks, fuzzy.check_rank);
  characters_.push_back(
      {&mesh, fuzzy, std::move(influences), std::move(rigid), influence_bounds(mesh, fuzzy.bone_count)});
  return static_cast<std::uint32_t>(characters_.size() - 1);
}

Expected<std::uint32_t> Scene::add_instance(std::uint32_t character) {
  if (character >= characters_.size()) {
    return invalid_argument("character", std::to_string(character), "no such character in the scene");
  }
  InstanceFrame frame;
  frame.character = character;
  frame.instance_id = static_cast<std::uint32_t>(slots_.size());
  frame.skinning.assign(characters_[character].fuzzy.bone_count, Affine3::identity());
  instances_.push_back(std::move(frame));
  slots_.push_back({ObjectKind::kCharacter, static_cast<std::uint32_t>(instances_.size() - 1)});
  return instances_.back().instance_id;
}

Expected<std::uint32_t> Scene::add_static_mesh(StaticMeshDesc mesh, const KdBuildOptions& kd) {
  const std::string id = "static_meshes[" + std::to_string(statics_.size()) + "]";
  SINEW_RETURN_IF_ERROR(check_triangle_mesh(MeshOrigin{id, ""}, mesh.positions, mesh.triangles,
                                            mesh.triangle_material, mesh.material_colors));
  std::vector<Aabb> boxes;
  boxes.reserve(mesh.triangles.size());
  for (const auto& triangle : mesh.triangles) {
    Aabb box;
    for (const std::uint32_t v : triangle) box.extend(mesh.positions[v]);
    boxes.push_back(box);
  }
  SINEW_ASSIGN_OR_RETURN(KdTree tree, build_kd_tree(boxes, within_traversal_depth(kd)));
  statics_.push_back({std::move(mesh), std::move(tree), static_cast<std::uint32_t>(slots_.size())});
  slots_.push_back({ObjectKind::kStatic, static_cast<std::uint32_t>(statics_.size() - 1)});
  return static_cast<std::uint32_t>(slots_.size() - 1);
}

bool Scene::contains(std::uint32_t id) const {
  if (id >= slots_.size()) return false;
  const ObjectSlot& slot = slots_[id];
  return slot.kind == ObjectKind::kCharacter ? instances_[slot.index].live : statics_[slot.index].live;
}

Status Scene::remove(std::uint32_t id) {
  if (!contains(id)) {
    return make_error(ErrorCode::kNotFound, "scene", "id", std::to_string(id),
                      id < slots_.size() ? "removed already" : "no such instance or static mesh");
  }
  const ObjectSlot& slot = slots_[id];
  if (slot.kind == ObjectKind::kCharacter) {
    InstanceFrame& frame = instances_[slot.index];
    InstanceFrame removed;
    removed.character = frame.character;
    removed.instance_id = frame.instance_id;
    removed.live = false;
    frame = std::move(removed);
  } else {
    StaticMesh& mesh = statics_[slot.index];
    mesh = StaticMesh{StaticMeshDesc{}, KdTree{}, mesh.instance_id, false};
  }
  return {};
}

Status Scene::set_mask(std::uint32_t id, std::uint32_t mask) {
  if (!contains(id)) {
    return make_error(ErrorCode::kNotFound, "scene", "id", std::to_string(id),
                      id < slots_.size() ? "removed" : "no such instance or static mesh");
  }
  const ObjectSlot& slot = slots_[id];
  if (slot.kind == ObjectKind::kCharacter) {
    instances_[slot.index].mask = mask;
  } else {
    statics_[slot.index].mask = mask;
  }
  top_level_.set_mask(slot.kind == ObjectKind::kStatic, slot.index, mask);
  return {};
}

Status Scene::set_bones(std::uint32_t instance, std::span<const Affine3> skinning) {
  if (instance >= slots_.size() || slots_[instance].kind != ObjectKind::kCharacter) {
    return invalid_argument("instance", std::to_string(instance), "not a character instance");
  }
  if (!contains(instance)) return invalid_argument("instance", std::to_string(instance), "removed");
  InstanceFrame& frame = instances_[slots_[instance].index];
  if (skinning.size() != frame.skinning.size()) {
    return invalid_argument("skinning", std::to_string(skinning.size()),
                            "expected one matrix per bone (" + std::to_string(frame.skinning.size()) + ")");
  }
  for (std::size_t b = 0; b < skinning.size(); ++b) {
    if (!is_finite(skinning[b])) {
      return invalid_argument("skinning[" + std::to_string(b) + "]", "", "matrix is not finite");
    }
  }
  frame.skinning.assign(skinning.begin(), skinning.end());
  return {};
}

Status Scene::cull_instances(const FrameOptions& options) {
  const bool by_rays = !options.rays.empty();
  if (!options.visibility && !by_rays) {
    for (InstanceFrame& frame : instances_) {
      frame.culled = false;
      frame.bounds = Aabb::empty();
    }
    return {};
  }
  float magnitude = 0.0f;
  for (InstanceFrame& frame : instances_) {
    frame.culled = false;
    if (!frame.live) continue;
    frame.bounds = instance_bounds(frame.skinning, characters_[frame.character].influence_bounds);
    magnitude = std::max(magnitude, max_abs(frame.bounds));
  }
  for (const StaticMesh& mesh : statics_) {
    if (mesh.live && !mesh.tree.nodes.empty()) magnitude = std::max(magnitude, max_abs(mesh.tree.bounds));
  }
  if (options.visibility && !cull_.begin(*options.visibility, magnitude)) return {};  // nothing culled
  // From here an instance is culled unless some ray can reach it.
  for (InstanceFrame& frame : instances_) frame.culled = frame.live;
  if (options.visibility) {
    // Camera rays first; then shadow rays, which start on what the camera
    // sees: the static meshes and the instances in view.
    Aabb in_view = Aabb::empty();
    for (InstanceFrame& frame : instances_) {
      if (!frame.live || !cull_.in_view(frame.bounds)) continue;
      frame.culled = false;
      in_view.extend(frame.bounds);
    }
    cull_.add_receivers(in_view);
    for (const StaticMesh& mesh : statics_) {
      if (mesh.live && !mesh.tree.nodes.empty()) cull_.add_receivers(mesh.tree.bounds);
    }
    cull_.finish_receivers();
    for (InstanceFrame& frame : instances_) {
      if (frame.culled && cull_.casts_into_view(frame.bounds)) frame.culled = false;
    }
  }
  if (by_rays) {
    // A hit rounds relative to the ray's origin and the triangle, which
    // lies in its instance's bounds.
    float scale = magnitude;
    for (const Ray& ray : options.rays) {
      const float origin = std::max({std::fabs(ray.origin.x), std::fabs(ray.origin.y), std::fabs(ray.origin.z)});
      if (std::isfinite(origin)) scale = std::max(scale, origin);
    }
    const double margin = FrameCull::kRelativeMargin * static_cast<double>(scale) +
                          static_cast<double>(std::numeric_limits<float>::min());
    reach_boxes_.resize(instances_.size());
    for (std::size_t i = 0; i < instances_.size(); ++i) {
      reach_boxes_[i] = instances_[i].culled ? instances_[i].bounds : Aabb::empty();
    }
    SINEW_RETURN_IF_ERROR(reach_.mark(options.rays, reach_boxes_, margin, reached_));
    for (std::size_t i = 0; i < instances_.size(); ++i) {
      if (reached_[i]) instances_[i].culled = false;
    }
  }
  return {};
}

Expected<FrameStats> Scene::prepare_frame(const FrameOptions& options, JobSystem& jobs,
                                          PhaseTimers* timers) {
  FrameStats stats;
  double skinning_ms = 0.0;
  double boxes_ms = 0.0;
  double fallback_ms = 0.0;
  auto start = std::chrono::steady_clock::now();
  SINEW_RETURN_IF_ERROR(cull_instances(options));  // timed as skinning's, the step it skips
  skinning_ms += ms_since(start);
  for (InstanceFrame& frame : instances_) {
    if (!frame.live) continue;
    if (frame.culled) {
      ++stats.culled_instances;
      frame.bone_world_boxes.assign(frame.skinning.size(), Aabb::empty());
      frame.escaped_triangles.clear();
      frame.fallback = KdTree{};
      frame.escaped_checks = frame.singular_bones = frame.cluster_bones = frame.cluster_misses = 0;
      continue;
    }
    ++stats.skinned_instances;
    const Character& character = characters_[frame.character];
    start = std::chrono::steady_clock::now();
    update_bone_frames(frame, character.fuzzy);
    choose_bone_clusters(frame, character.fuzzy, options.pose_clusters);
    skin_instance(frame, scratch_, *character.mesh, character.influences, character.fuzzy, character.rigid_blocks,
                  options.normals, options.bone_boxes == BoneBoxMode::kExact, options.skinning, jobs);
    settle_bone_clusters(frame, scratch_, character.fuzzy, character.rigid_blocks, jobs);
    frame.leaf_boxes.prepare(character.fuzzy);
    skinning_ms += ms_since(start);

    start = std::chrono::steady_clock::now();
    compute_bone_boxes(frame, scratch_, character.fuzzy, options.bone_boxes == BoneBoxMode::kExact);
    boxes_ms += ms_since(start);

    start = std::chrono::steady_clock::now();
    if (options.fallback) {
      SINEW_RETURN_IF_ERROR(build_fallback(frame, scratch_, *character.mesh, character.fuzzy,
                                           within_traversal_depth(options.fallback_kd)));
    } else {
      frame.escaped_triangles.clear();
      frame.fallback = KdTree{};
    }
    fallback_ms += ms_since(start);
    stats.escaped_checks += frame.escaped_checks;
    stats.escaped_triangles += frame.escaped_triangles.size();
    stats.singular_bones += frame.singular_bones;
    stats.cluster_bones += frame.cluster_bones;
    stats.cluster_misses += frame.cluster_misses;
  }

  start = std::chrono::steady_clock::now();
  std::vector<TopLevelObject> objects = top_level_.take_objects();
  for (std::uint32_t i = 0; i < instances_.size(); ++i) {
    const InstanceFrame& frame = instances_[i];
    if (!frame.live || frame.culled) continue;
    const FuzzyCharacterView& fuzzy = characters_[frame.character].fuzzy;
    for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
      if (fuzzy.bone_trees[b].triangle_count == 0 || fuzzy.bone_trees[b].node_count == 0 ||
          !frame.bone_usable[b] || frame.bone_world_boxes[b].is_empty()) {
        continue;
      }
      objects.push_back({TopLevelObject::Kind::kBone, i, b, frame.bone_world_boxes[b], frame.mask});
    }
    if (!frame.fallback.nodes.empty()) {
      objects.push_back({TopLevelObject::Kind::kFallback, i, 0, frame.fallback.bounds, frame.mask});
    }
  }
  for (std::uint32_t s = 0; s < statics_.size(); ++s) {
    if (!statics_[s].live || statics_[s].tree.nodes.empty()) continue;
    objects.push_back({TopLevelObject::Kind::kStatic, s, 0, statics_[s].tree.bounds, statics_[s].mask});
  }
  SINEW_RETURN_IF_ERROR(top_level_.build(std::move(objects), within_traversal_depth(options.top_level_kd)));
  const double top_ms = ms_since(start);
  stats.top_level_objects = static_cast<std::uint32_t>(top_level_.objects().size());
  stats.top_level_nodes = top_level_.stats().node_count;
  stats.fallback_ms = stats.escaped_triangles > 0 ? fallback_ms : 0.0;  // nothing escaped: no tree built

  if (timers) {
    timers->record("skinning", skinning_ms);
    timers->record("boxes", boxes_ms);
    timers->record("fallback", fallback_ms);
    timers->record("top level", top_ms);
  }
  return stats;
}

}  // namespace sinew::rt
