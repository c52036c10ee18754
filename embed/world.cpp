// sinew::api::World: instances in an rt::Scene, posed by anim::Mixer or by
// the host's matrices.
#include <cmath>
#include <string>

#include "animation/joint_limits.h"
#include "animation/pose.h"
#include "embed/api_errors.h"
#include "embed/convert.h"
#include "embed/world_impl.h"

namespace sinew::api {
namespace {

using Instance = World::Impl::Instance;

// A cap far above any scene, well below where ids or memory become a problem.
constexpr std::size_t kMaxInstances = std::size_t{1} << 24;

bool finite(const Matrix3x4& m) {
  for (const auto& row : m.m) {
    for (float v : row) {
      if (!std::isfinite(v)) return false;
    }
  }
  return true;
}

bool finite(float v) { return std::isfinite(v); }

// The clip's index in the model, by name or "#<index>".
Result<int> clip_index(const Instance& instance, std::string_view clip) {
  const auto& model = instance.core->model();
  if (const anim::Clip* found = model.find_clip(std::string(clip))) {
    return static_cast<int>(found - model.clips.data());
  }
  std::string names;
  for (const anim::Clip& c : model.clips) names += (names.empty() ? "" : ", ") + c.name();
  return detail::api_error(ErrorCode::kNotFound, instance.core->name + ": clip '" + std::string(clip) +
                                                     "': no such clip (clips: " + (names.empty() ? "none" : names) + ")");
}

void reset_mixer(Instance& instance) {
  const auto& model = instance.core->model();
  instance.mixer = std::make_unique<anim::Mixer>(std::span<const anim::Clip>(model.clips));
  instance.caches.assign(model.clips.size(), {});
}

// `instance.local` -> limits -> model space -> skinning matrices -> the scene.
Status finish_pose(World::Impl& world, InstanceId id) {
  world.changed();
  Instance& instance = world.instances[id];
  const character::Model& model = instance.core->model();
  if (instance.limits && !instance.core->pack.limits().empty()) {
    SINEW_RETURN_IF_ERROR_API(anim::apply_joint_limits(model.skeleton, instance.core->pack.limits(), instance.local));
  }
  SINEW_RETURN_IF_ERROR_API(anim::local_to_model(model.skeleton, instance.local, instance.model_pose));
  SINEW_RETURN_IF_ERROR_API(
      anim::skinning_matrices(model.skeleton, instance.model_pose, instance.transform, instance.skin));
  return detail::to_api_status(world.scene.set_bones(id, instance.skin));
}

}  // namespace

namespace detail {

Result<Instance*> find_character(World::Impl& world, InstanceId id, const char* call) {
  if (id >= world.instances.size() || world.instances[id].is_static || world.instances[id].removed) {
    const bool removed = id < world.instances.size() && world.instances[id].removed;
    return detail::api_error(ErrorCode::kNotFound,
                             std::string(call) + ": instance " + std::to_string(id) + ": " +
                                 (removed ? "removed (World::remove)" : "no such character instance"));
  }
  return &world.instances[id];
}

Result<Instance*> find_instance(World::Impl& world, InstanceId id, Driver wanted, const char* call) {
  const auto found = find_character(world, id, call);
  if (!found.ok()) return found.error();
  Instance& instance = **found;
  if (instance.driver != wanted) {
    return detail::api_error(ErrorCode::kInvalidArgument,
                             std::string(call) + ": instance " + std::to_string(id) + " is " +
                                 (instance.driver == Driver::kHost ? "host-driven" : "mixer-driven") +
                                 " (InstanceDesc::driver)");
  }
  return &instance;
}

Status pose_from_mixer(World::Impl& world, InstanceId id) {
  Instance& instance = world.instances[id];
  const character::Model& model = instance.core->model();
  SINEW_RETURN_IF_ERROR_API(anim::evaluate_layers(model.skeleton, model.clips, instance.mixer->layers(),
                                                  instance.caches, instance.local, &instance.scratch));
  return finish_pose(world, id);
}

}  // namespace detail

World::World(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

Result<World> World::create() noexcept {
  return detail::guarded("World::create", [&]() -> Result<World> { return World(std::make_unique<Impl>()); });
}

Result<InstanceId> World::add_instance(const Character& character, const InstanceDesc& desc) noexcept {
  return detail::guarded("World::add_instance", [&]() -> Result<InstanceId> {
    if (!finite(desc.transform)) {
      return detail::api_error(ErrorCode::kInvalidArgument, "World::add_instance: desc.transform: not finite");
    }
    if (!finite(desc.playback_speed) || desc.playback_speed < 0.0f) {
      return detail::api_error(ErrorCode::kInvalidArgument,
                               "World::add_instance: desc.playback_speed = " + std::to_string(desc.playback_speed) +
                                   ": expected a finite speed >= 0");
    }
    if (impl_->instances.size() >= kMaxInstances) {
      return detail::api_error(ErrorCode::kLimitExceeded,
                               "World::add_instance: " + std::to_string(kMaxInstances) + " instances already");
    }
    std::shared_ptr<const Character::Impl> core = CharacterFactory::share(character);
    // Instances of one character share its scene character (and trees).
    std::uint32_t scene_character = 0;
    while (scene_character < impl_->cores.size() && impl_->cores[scene_character] != core) ++scene_character;
    if (scene_character == impl_->cores.size()) {
      const auto added = impl_->scene.add_character(core->model().mesh, core->pack.fuzzy());
      if (!added.ok()) return detail::to_api_error(added.status());
      impl_->cores.push_back(core);
    }
    const auto id = impl_->scene.add_instance(scene_character);
    if (!id.ok()) return detail::to_api_error(id.status());
    SINEW_RETURN_IF_ERROR_API(impl_->scene.set_mask(*id, desc.mask));

    if (impl_->instances.size() <= *id) impl_->instances.resize(*id + 1);
    Instance& instance = impl_->instances[*id];
    instance.core = core;
    instance.driver = desc.driver;
    instance.transform = desc.driver == Driver::kMixer ? detail::to_internal(desc.transform) : Affine3::identity();
    instance.limits = desc.apply_joint_limits;
    instance.speed = desc.playback_speed;
    const std::size_t joints = core->model().skeleton.joint_count();
    instance.local.resize(joints);
    instance.model_pose.resize(joints);
    instance.skin.resize(joints);
    if (desc.driver == Driver::kMixer) reset_mixer(instance);
    // Both drivers start at the bind pose (host-driven: in model space).
    SINEW_RETURN_IF_ERROR_API(anim::rest_pose(core->model().skeleton, instance.local));
    const Status posed = finish_pose(*impl_, *id);
    if (!posed.ok()) return posed.error();
    return static_cast<InstanceId>(*id);
  });
}

Result<InstanceId> World::add_static_mesh(const StaticMeshDesc& mesh) noexcept {
  return detail::guarded("World::add_static_mesh", [&]() -> Result<InstanceId> {
    const auto bad = [](const std::string& what) {
      return detail::api_error(ErrorCode::kInvalidArgument, "World::add_static_mesh: " + what);
    };
    if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) {
      return bad("indices: " + std::to_string(mesh.indices.size()) + " entries, expected a positive multiple of 3");
    }
    if (impl_->instances.size() >= kMaxInstances) {
      return detail::api_error(ErrorCode::kLimitExceeded,
                               "World::add_static_mesh: " + std::to_string(kMaxInstances) + " instances already");
    }
    rt::StaticMeshDesc desc;
    desc.positions.reserve(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      const Float3& p = mesh.positions[i];
      if (!finite(p.x) || !finite(p.y) || !finite(p.z)) return bad("positions[" + std::to_string(i) + "]: not finite");
      desc.positions.push_back(detail::to_internal(p));
    }
    desc.triangles.reserve(mesh.indices.size() / 3);
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
      std::array<std::uint32_t, 3> tri{mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
      for (std::size_t c = 0; c < 3; ++c) {
        if (tri[c] >= mesh.positions.size()) {
          return bad("indices[" + std::to_string(t + c) + "]: " + std::to_string(tri[c]) + ", past the " +
                     std::to_string(mesh.positions.size()) + " positions");
        }
      }
      desc.triangles.push_back(tri);
    }
    if (!finite(mesh.color.x) || !finite(mesh.color.y) || !finite(mesh.color.z)) return bad("color: not finite");
    desc.material_colors = {detail::to_internal(mesh.color)};
    const auto id = impl_->scene.add_static_mesh(std::move(desc));
    if (!id.ok()) return detail::to_api_error(id.status());
    SINEW_RETURN_IF_ERROR_API(impl_->scene.set_mask(*id, mesh.mask));
    if (impl_->instances.size() <= *id) impl_->instances.resize(*id + 1);
    impl_->instances[*id].is_static = true;
    impl_->changed();
    return static_cast<InstanceId>(*id);
  });
}

Status World::set_bone_matrices(InstanceId id, std::span<const Matrix3x4> skinning) noexcept {
  return detail::guarded("World::set_bone_matrices", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kHost, "World::set_bone_matrices");
    if (!found.ok()) return found.error();
    Instance& instance = **found;
    if (skinning.size() != instance.skin.size()) {
      return detail::api_error(ErrorCode::kInvalidArgument,
                               "World::set_bone_matrices: instance " + std::to_string(id) + ": " +
                                   std::to_string(skinning.size()) + " matrices, the character has " +
                                   std::to_string(instance.skin.size()) + " bones");
    }
    for (std::size_t b = 0; b < skinning.size(); ++b) {
      if (!finite(skinning[b])) {
        return detail::api_error(ErrorCode::kInvalidArgument,
                                 "World::set_bone_matrices: instance " + std::to_string(id) + ": skinning[" +
                                     std::to_string(b) + "] (bone '" +
                                     instance.core->model().skeleton.names()[b] + "'): not finite");
      }
    }
    for (std::size_t b = 0; b < skinning.size(); ++b) instance.skin[b] = detail::to_internal(skinning[b]);
    impl_->changed();
    return detail::to_api_status(impl_->scene.set_bones(id, instance.skin));
  });
}

Status World::set_transform(InstanceId id, const Matrix3x4& model_to_world) noexcept {
  return detail::guarded("World::set_transform", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::set_transform");
    if (!found.ok()) return found.error();
    if (!finite(model_to_world)) {
      return detail::api_error(ErrorCode::kInvalidArgument, "World::set_transform: model_to_world: not finite");
    }
    (*found)->transform = detail::to_internal(model_to_world);
    return finish_pose(*impl_, id);  // the current local pose, placed anew
  });
}

Status World::play_cycle(InstanceId id, std::string_view clip, float weight, float fade_seconds) noexcept {
  return detail::guarded("World::play_cycle", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::play_cycle");
    if (!found.ok()) return found.error();
    const auto index = clip_index(**found, clip);
    if (!index.ok()) return index.error();
    anim::Mixer& mixer = *(*found)->mixer;
    const bool idle = mixer.animation_duration() == 0.0f;
    SINEW_RETURN_IF_ERROR_API(mixer.blend_cycle(*index, weight, fade_seconds));
    // Start the clock now, so the host's next advance(dt) is dt of playing.
    if (idle) mixer.update(0.0f);
    return Status();
  });
}

Status World::stop_cycle(InstanceId id, std::string_view clip, float fade_seconds) noexcept {
  return detail::guarded("World::stop_cycle", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::stop_cycle");
    if (!found.ok()) return found.error();
    const auto index = clip_index(**found, clip);
    if (!index.ok()) return index.error();
    return detail::to_api_status((*found)->mixer->clear_cycle(*index, fade_seconds));
  });
}

Status World::play_action(InstanceId id, std::string_view clip, float fade_in_seconds,
                          float fade_out_seconds) noexcept {
  return detail::guarded("World::play_action", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::play_action");
    if (!found.ok()) return found.error();
    const auto index = clip_index(**found, clip);
    if (!index.ok()) return index.error();
    return detail::to_api_status((*found)->mixer->execute_action(*index, fade_in_seconds, fade_out_seconds));
  });
}

Status World::pose_at(InstanceId id, std::string_view clip, double seconds) noexcept {
  return detail::guarded("World::pose_at", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::pose_at");
    if (!found.ok()) return found.error();
    if (!std::isfinite(seconds)) {
      return detail::api_error(ErrorCode::kInvalidArgument, "World::pose_at: seconds: not finite");
    }
    Instance& instance = **found;
    const auto index = clip_index(instance, clip);
    if (!index.ok()) return index.error();
    reset_mixer(instance);
    const character::Model& model = instance.core->model();
    const anim::Clip& c = model.clips[static_cast<std::size_t>(*index)];
    SINEW_RETURN_IF_ERROR_API(anim::rest_pose(model.skeleton, instance.local));
    anim::sample_clip(c, anim::clip_time(c, seconds, /*loop=*/true), instance.caches[static_cast<std::size_t>(*index)],
                      instance.local);
    return finish_pose(*impl_, id);
  });
}

Status World::advance(float dt_seconds) noexcept {
  return detail::guarded("World::advance", [&]() -> Status {
    if (!std::isfinite(dt_seconds) || dt_seconds < 0.0f) {
      return detail::api_error(ErrorCode::kInvalidArgument,
                               "World::advance: dt_seconds = " + std::to_string(dt_seconds) +
                                   ": expected a finite time >= 0");
    }
    const auto moves = [](const Instance& i) { return !i.removed && !i.is_static && i.driver == Driver::kMixer; };
    // Checked for every instance first, so an error leaves all of them unmoved.
    for (InstanceId id = 0; id < impl_->instances.size(); ++id) {
      const Instance& instance = impl_->instances[id];
      if (moves(instance) && !std::isfinite(dt_seconds * instance.speed)) {
        return detail::api_error(ErrorCode::kInvalidArgument,
                                 "World::advance: instance " + std::to_string(id) + ": dt_seconds = " +
                                     std::to_string(dt_seconds) + " times playback speed " +
                                     std::to_string(instance.speed) + " is not a finite time");
      }
    }
    for (InstanceId id = 0; id < impl_->instances.size(); ++id) {
      Instance& instance = impl_->instances[id];
      if (!moves(instance)) continue;
      instance.mixer->update(dt_seconds * instance.speed);
      const Status posed = detail::pose_from_mixer(*impl_, id);
      if (!posed.ok()) return posed;
    }
    return Status();
  });
}

Status World::remove(InstanceId id) noexcept {
  return detail::guarded("World::remove", [&]() -> Status {
    if (id >= impl_->instances.size() || impl_->instances[id].removed) {
      return detail::api_error(ErrorCode::kNotFound,
                               "World::remove: instance " + std::to_string(id) + ": " +
                                   (id < impl_->instances.size() ? "removed already"
                                                                 : "no such instance or static mesh"));
    }
    SINEW_RETURN_IF_ERROR_API(impl_->scene.remove(id));
    // Its mixer, poses and share of the character go; the character's
    // scene entry (and trees) stay for later instances of it.
    Instance removed;
    removed.removed = true;
    removed.is_static = impl_->instances[id].is_static;
    impl_->instances[id] = std::move(removed);
    impl_->changed();
    return Status();
  });
}

Status World::set_mask(InstanceId id, std::uint32_t mask) noexcept {
  return detail::guarded("World::set_mask", [&]() -> Status {
    if (id >= impl_->instances.size() || impl_->instances[id].removed) {
      return detail::api_error(ErrorCode::kNotFound,
                               "World::set_mask: instance " + std::to_string(id) + ": " +
                                   (id < impl_->instances.size() ? "removed" : "no such instance or static mesh"));
    }
    // The scene patches its top level in place: no prepare is owed.
    SINEW_RETURN_IF_ERROR_API(impl_->scene.set_mask(id, mask));
    return Status();
  });
}

std::size_t World::instance_count() const noexcept {
  std::size_t live = 0;
  for (const Instance& instance : impl_->instances) live += instance.removed ? 0 : 1;
  return live;
}

}  // namespace sinew::api
