// sinew::api::Character over character::Pack.
#include <cmath>
#include <string>

#include "animation/pose_space.h"
#include "character/framing.h"
#include "embed/api_errors.h"
#include "embed/character_impl.h"
#include "embed/convert.h"
#include "runtime/math/aabb.h"
#include "runtime/pack/pack_format.h"
#include "sinew/version.h"

namespace sinew::api {
Result<Character> CharacterFactory::make(character::Pack pack, std::string name) {
  if (!pack.has_fuzzy()) {
    return detail::api_error(ErrorCode::kUnsupported,
                             name + ": a model-only pack (no fuzzy kd-trees): bake it first "
                                    "(sinew-editor bake MODEL -o OUT.pack)");
  }
  auto impl = std::make_shared<Character::Impl>(std::move(pack));
  impl->name = std::move(name);
  return Character(std::move(impl));
}

namespace {

Result<Character> adopt(Expected<character::Pack> pack, std::string name) {
  if (!pack.ok()) return detail::to_api_error(pack.status());
  return CharacterFactory::make(std::move(*pack), std::move(name));
}

}  // namespace

Result<Character> Character::load(std::string_view path) noexcept {
  return detail::guarded("Character::load", [&]() -> Result<Character> {
    const std::string p(path);
    return adopt(character::Pack::open(p), p);
  });
}

Result<Character> Character::from_memory(std::span<const std::byte> bytes, std::string_view name) noexcept {
  return detail::guarded("Character::from_memory", [&]() -> Result<Character> {
    const std::string n(name);
    return adopt(character::Pack::from_bytes(bytes, n), n);
  });
}

std::size_t Character::bone_count() const noexcept { return impl_->model().skeleton.joint_count(); }

std::string_view Character::bone_name(std::size_t bone) const noexcept {
  const auto names = impl_->model().skeleton.names();
  return bone < names.size() ? std::string_view(names[bone]) : std::string_view();
}

Result<std::size_t> Character::find_bone(std::string_view name) const noexcept {
  return detail::guarded("Character::find_bone", [&]() -> Result<std::size_t> {
    if (const auto index = impl_->model().skeleton.find(name)) return static_cast<std::size_t>(*index);
    return detail::api_error(ErrorCode::kNotFound, impl_->name + ": bone '" + std::string(name) + "': no such bone");
  });
}

Matrix3x4 Character::bind_pose(std::size_t bone) const noexcept {
  const auto inverse_bind = impl_->model().skeleton.inverse_bind();
  if (bone >= inverse_bind.size()) return Matrix3x4::identity();
  return detail::to_api(inverse(inverse_bind[bone]));
}

int Character::bone_parent(std::size_t bone) const noexcept {
  const auto parents = impl_->model().skeleton.parents();
  return bone < parents.size() ? parents[bone] : -1;
}

std::size_t Character::clip_count() const noexcept { return impl_->model().clips.size(); }

std::string_view Character::clip_name(std::size_t clip) const noexcept {
  const auto& clips = impl_->model().clips;
  return clip < clips.size() ? std::string_view(clips[clip].name()) : std::string_view();
}

std::size_t Character::material_count() const noexcept { return impl_->model().mesh.material_colors.size(); }

std::string_view Character::material_name(std::size_t material) const noexcept {
  const auto& names = impl_->model().material_names;
  return material < names.size() ? std::string_view(names[material]) : std::string_view();
}

bool Character::material_has_texture(std::size_t material) const noexcept {
  const auto& textured = impl_->model().mesh.material_texture;
  return material < textured.size() && textured[material] != kNoTexture;
}

float Character::clip_duration(std::size_t clip) const noexcept {
  const auto& clips = impl_->model().clips;
  return clip < clips.size() ? clips[clip].duration() : 0.0f;
}

Character::Bounds Character::bind_bounds() const noexcept {
  const auto& positions = impl_->model().mesh.positions;
  if (positions.empty()) return {};
  Aabb box;
  for (const Vec3& p : positions) box.extend(p);
  return {detail::to_api(box.lower), detail::to_api(box.upper)};
}

Character::Framing Character::framing(float aspect) const noexcept {
  const character::PackFraming& stored = impl_->pack.framing();
  const Aabb& box = stored.rest_bounds;
  // A degenerate aspect (not finite or not positive) is taken as square.
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
  Framing f;
  f.up_axis = stored.up_axis;
  f.rest_bounds = {detail::to_api(box.lower), detail::to_api(box.upper)};
  const rt::CameraDesc camera = character::default_camera(box, stored.up_axis, aspect);
  f.camera.eye = detail::to_api(camera.eye);
  f.camera.target = detail::to_api(camera.target);
  f.camera.up = detail::to_api(camera.up);
  f.camera.fovy_degrees = camera.fovy_degrees;
  f.light.kind = Light::Kind::kPoint;
  f.light.position = detail::to_api(character::default_light(box, stored.up_axis));
  return f;
}

std::size_t Character::vertex_count() const noexcept { return impl_->model().mesh.vertex_count(); }
std::size_t Character::triangle_count() const noexcept { return impl_->model().mesh.triangle_count(); }

std::string Character::pose_space() const {
  const auto& record = impl_->pack.pose_space();
  return std::string(anim::pose_space_mode_name(record.desc.mode)) + " (" +
         std::to_string(impl_->pack.fuzzy_stats().sample_count) + " samples)";
}

std::string_view Character::source_name() const noexcept { return impl_->name; }

Version library_version() noexcept { return {SINEW_VERSION_MAJOR, SINEW_VERSION_MINOR, SINEW_VERSION_PATCH}; }

Version pack_format_version() noexcept { return {kPackVersionMajor, kPackVersionMinor, 0}; }

}  // namespace sinew::api
