#include "raytrace/scene/scene.h"

#include <chrono>
#include <string>
#include <utility>

#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::rt {
namespace {

Status bad_character(std::string_view field, std::string value, std::string_view detail) {
  return make_error(ErrorCode::kInvalidData, "character", field, value, detail);
}

// Checks what traversal relies on so that a corrupt pack or a mismatched
// bake cannot make it read out of bounds: node links, leaf item ranges and
// depth within each bone's slice, item values within the triangle count.
Status validate_tree(const KdTreeView& tree, std::uint32_t item_limit, std::uint32_t bone) {
  const std::string where = "bone_trees[" + std::to_string(bone) + "]";
  struct Pending {
    std::uint32_t node;
    int depth;
  };
  std::vector<Pending> stack;
  if (!tree.nodes.empty()) stack.push_back({0, 0});
  std::size_t visited = 0;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    if (++visited > tree.nodes.size()) return bad_character(where, "", "kd-tree nodes form a cycle");
    if (p.depth > kMaxTraversalDepth) {
      return bad_character(where, std::to_string(p.depth), "kd-tree deeper than the traversal supports");
    }
    const KdNode& node = tree.nodes[p.node];
    if (node.is_leaf()) {
      if (std::size_t{node.first_item()} + node.item_count() > tree.items.size()) {
        return bad_character(where + ".nodes[" + std::to_string(p.node) + "]",
                             std::to_string(node.first_item()), "leaf items outside the item array");
      }
      continue;
    }
    if (p.node + 1 >= tree.nodes.size() || node.above_child() >= tree.nodes.size() ||
        node.above_child() <= p.node) {
      return bad_character(where + ".nodes[" + std::to_string(p.node) + "]",
                           std::to_string(node.above_child()), "child index outside the tree");
    }
    if (!std::isfinite(node.split())) {
      return bad_character(where + ".nodes[" + std::to_string(p.node) + "]", "", "split is not finite");
    }
    stack.push_back({p.node + 1, p.depth + 1});
    stack.push_back({node.above_child(), p.depth + 1});
  }
  for (std::size_t i = 0; i < tree.items.size(); ++i) {
    if (tree.items[i] >= item_limit) {
      return bad_character(where + ".items[" + std::to_string(i) + "]", std::to_string(tree.items[i]),
                           "not a triangle of the mesh");
    }
  }
  return {};
}

Status validate_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  const std::size_t vertices = mesh.vertex_count();
  const std::size_t triangles = mesh.triangle_count();
  if (fuzzy.bone_count == 0 || fuzzy.bone_trees.size() != fuzzy.bone_count) {
    return bad_character("bone_trees", std::to_string(fuzzy.bone_trees.size()),
                         "expected one tree per bone (" + std::to_string(fuzzy.bone_count) + ")");
  }
  if (fuzzy.triangle_bone.size() != triangles || fuzzy.triangle_checks.size() != triangles) {
    return bad_character("triangle_bone", std::to_string(fuzzy.triangle_bone.size()),
                         "expected one entry per triangle (" + std::to_string(triangles) + ")");
  }
  if (fuzzy.vertex_check_begin.size() != vertices + 1 || fuzzy.vertex_check_begin.front() != 0 ||
      fuzzy.vertex_check_begin.back() != fuzzy.vertex_checks.size()) {
    return bad_character("vertex_check_begin", std::to_string(fuzzy.vertex_check_begin.size()),
                         "expected vertex_count + 1 offsets covering the checks");
  }
  if (mesh.joints.size() != vertices || mesh.weights.size() != vertices ||
      (!mesh.normals.empty() && mesh.normals.size() != vertices)) {
    return bad_character("mesh", std::to_string(vertices), "per-vertex arrays differ in length");
  }
  for (std::size_t v = 0; v < vertices; ++v) {
    if (fuzzy.vertex_check_begin[v] > fuzzy.vertex_check_begin[v + 1]) {
      return bad_character("vertex_check_begin[" + std::to_string(v) + "]",
                           std::to_string(fuzzy.vertex_check_begin[v]), "offsets decrease");
    }
    for (const std::uint16_t j : mesh.joints[v]) {
      if (j >= fuzzy.bone_count) {
        return bad_character("joints[" + std::to_string(v) + "]", std::to_string(j), "no such bone");
      }
    }
  }
  for (std::size_t c = 0; c < fuzzy.vertex_checks.size(); ++c) {
    if (fuzzy.vertex_checks[c].bone >= fuzzy.bone_count) {
      return bad_character("vertex_checks[" + std::to_string(c) + "].bone",
                           std::to_string(fuzzy.vertex_checks[c].bone), "no such bone");
    }
  }
  for (std::size_t t = 0; t < triangles; ++t) {
    if (fuzzy.triangle_bone[t] >= fuzzy.bone_count) {
      return bad_character("triangle_bone[" + std::to_string(t) + "]",
                           std::to_string(fuzzy.triangle_bone[t]), "no such bone");
    }
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.triangles[t][static_cast<std::size_t>(i)];
      const std::uint32_t c = fuzzy.triangle_checks[t][static_cast<std::size_t>(i)];
      if (v >= vertices) {
        return bad_character("triangles[" + std::to_string(t) + "]", std::to_string(v), "no such vertex");
      }
      // Each corner's check must be the vertex's check in the triangle's
      // bone: the fallback and escape logic read it as such.
      if (c < fuzzy.vertex_check_begin[v] || c >= fuzzy.vertex_check_begin[v + 1] ||
          fuzzy.vertex_checks[c].bone != fuzzy.triangle_bone[t]) {
        return bad_character("triangle_checks[" + std::to_string(t) + "]", std::to_string(c),
                             "not the corner vertex's check in the triangle's bone");
      }
    }
  }
  for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
    const BoneTree& tree = fuzzy.bone_trees[b];
    if (std::size_t{tree.node_begin} + tree.node_count > fuzzy.nodes.size() ||
        std::size_t{tree.item_begin} + tree.item_count > fuzzy.items.size()) {
      return bad_character("bone_trees[" + std::to_string(b) + "]", std::to_string(tree.node_begin),
                           "slice outside the node or item array");
    }
    SINEW_RETURN_IF_ERROR(validate_tree(fuzzy.bone_tree(b), static_cast<std::uint32_t>(triangles), b));
  }
  return {};
}

// Trees built here are traversed with a fixed stack: cap their depth.
KdBuildOptions within_traversal_depth(KdBuildOptions options) {
  if (options.max_depth <= 0 || options.max_depth > kMaxTraversalDepth) {
    options.max_depth = options.max_depth <= 0 ? 0 : kMaxTraversalDepth;
  }
  return options;
}

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Expected<std::uint32_t> Scene::add_character(const SkinnedMesh& mesh, const FuzzyCharacterView& fuzzy) {
  SINEW_RETURN_IF_ERROR(validate_character(mesh, fuzzy));
  characters_.push_back({&mesh, fuzzy});
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
  std::vector<Aabb> boxes;
  boxes.reserve(mesh.triangles.size());
  for (std::size_t p = 0; p < mesh.positions.size(); ++p) {
    const Vec3& v = mesh.positions[p];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
      return make_error(ErrorCode::kInvalidData, id, "positions[" + std::to_string(p) + "]", "",
                        "not finite");
    }
  }
  if (!mesh.triangle_material.empty() && mesh.triangle_material.size() != mesh.triangles.size()) {
    return make_error(ErrorCode::kInvalidData, id, "triangle_material",
                      std::to_string(mesh.triangle_material.size()), "expected one per triangle");
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    Aabb box;
    for (const std::uint32_t v : mesh.triangles[t]) {
      if (v >= mesh.positions.size()) {
        return make_error(ErrorCode::kInvalidData, id, "triangles[" + std::to_string(t) + "]",
                          std::to_string(v), "no such vertex");
      }
      box.extend(mesh.positions[v]);
    }
    if (!mesh.triangle_material.empty() && mesh.triangle_material[t] >= std::max<std::size_t>(1, mesh.material_colors.size())) {
      return make_error(ErrorCode::kInvalidData, id, "triangle_material[" + std::to_string(t) + "]",
                        std::to_string(mesh.triangle_material[t]), "no such material");
    }
    boxes.push_back(box);
  }
  SINEW_ASSIGN_OR_RETURN(KdTree tree, build_kd_tree(boxes, within_traversal_depth(kd)));
  statics_.push_back({std::move(mesh), std::move(tree), static_cast<std::uint32_t>(slots_.size())});
  slots_.push_back({ObjectKind::kStatic, static_cast<std::uint32_t>(statics_.size() - 1)});
  return static_cast<std::uint32_t>(slots_.size() - 1);
}

Status Scene::set_bones(std::uint32_t instance, std::span<const Affine3> skinning) {
  if (instance >= slots_.size() || slots_[instance].kind != ObjectKind::kCharacter) {
    return invalid_argument("instance", std::to_string(instance), "not a character instance");
  }
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

Expected<FrameStats> Scene::prepare_frame(const FrameOptions& options, JobSystem& jobs,
                                          PhaseTimers* timers) {
  FrameStats stats;
  double skinning_ms = 0.0;
  double boxes_ms = 0.0;
  double fallback_ms = 0.0;
  for (InstanceFrame& frame : instances_) {
    const Character& character = characters_[frame.character];
    auto start = std::chrono::steady_clock::now();
    update_bone_frames(frame, character.fuzzy);
    skin_instance(frame, *character.mesh, character.fuzzy, options.normals, options.skinning, jobs);
    skinning_ms += elapsed_ms(start);

    start = std::chrono::steady_clock::now();
    compute_bone_boxes(frame, character.fuzzy, options.bone_boxes == BoneBoxMode::kExact, jobs);
    boxes_ms += elapsed_ms(start);

    start = std::chrono::steady_clock::now();
    if (options.fallback) {
      SINEW_RETURN_IF_ERROR(build_fallback(frame, *character.mesh, character.fuzzy,
                                           within_traversal_depth(options.fallback_kd)));
    } else {
      frame.escaped_triangles.clear();
      frame.fallback = KdTree{};
    }
    fallback_ms += elapsed_ms(start);
    stats.escaped_checks += frame.escaped_checks;
    stats.escaped_triangles += frame.escaped_triangles.size();
    stats.singular_bones += frame.singular_bones;
  }

  const auto start = std::chrono::steady_clock::now();
  std::vector<TopLevelObject> objects = top_level_.take_objects();
  for (std::uint32_t i = 0; i < instances_.size(); ++i) {
    const InstanceFrame& frame = instances_[i];
    const FuzzyCharacterView& fuzzy = characters_[frame.character].fuzzy;
    for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
      if (fuzzy.bone_trees[b].triangle_count == 0 || fuzzy.bone_trees[b].node_count == 0 ||
          !frame.bone_usable[b] || frame.bone_world_boxes[b].is_empty()) {
        continue;
      }
      objects.push_back({TopLevelObject::Kind::kBone, i, b, frame.bone_world_boxes[b]});
    }
    if (!frame.fallback.nodes.empty()) {
      objects.push_back({TopLevelObject::Kind::kFallback, i, 0, frame.fallback.bounds});
    }
  }
  for (std::uint32_t s = 0; s < statics_.size(); ++s) {
    if (statics_[s].tree.nodes.empty()) continue;
    objects.push_back({TopLevelObject::Kind::kStatic, s, 0, statics_[s].tree.bounds});
  }
  SINEW_RETURN_IF_ERROR(top_level_.build(std::move(objects), within_traversal_depth(options.top_level_kd)));
  const double top_ms = elapsed_ms(start);
  stats.top_level_objects = static_cast<std::uint32_t>(top_level_.objects().size());
  stats.top_level_nodes = top_level_.stats().node_count;

  if (timers) {
    timers->record("skinning", skinning_ms);
    timers->record("boxes", boxes_ms);
    timers->record("fallback", fallback_ms);
    timers->record("top level", top_ms);
  }
  return stats;
}

}  // namespace sinew::rt
