// sinew::api::World: each mixer-driven instance's own clock (playback speed,
// time offset, Cal3D's time factor) and bone transforms read back for
// attachments.
#include <cmath>
#include <string>

#include "embed/api_errors.h"
#include "embed/convert.h"
#include "embed/world_impl.h"

namespace sinew::api {
namespace {

Error bad_value(const char* call, InstanceId id, const char* name, float value, const char* expected) {
  return detail::api_error(ErrorCode::kInvalidArgument, std::string(call) + ": instance " + std::to_string(id) +
                                                            ": " + name + " = " + std::to_string(value) +
                                                            ": expected " + expected);
}

}  // namespace

Status World::set_playback_speed(InstanceId id, float speed) noexcept {
  return detail::guarded("World::set_playback_speed", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::set_playback_speed");
    if (!found.ok()) return found.error();
    if (!std::isfinite(speed) || speed < 0.0f) {
      return bad_value("World::set_playback_speed", id, "speed", speed, "a finite speed >= 0");
    }
    (*found)->speed = speed;
    return Status();
  });
}

Status World::offset_time(InstanceId id, float seconds) noexcept {
  return detail::guarded("World::offset_time", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::offset_time");
    if (!found.ok()) return found.error();
    if (!std::isfinite(seconds) || seconds < 0.0f) {
      return bad_value("World::offset_time", id, "seconds", seconds, "a finite time >= 0");
    }
    (*found)->mixer->update(seconds);
    return detail::pose_from_mixer(*impl_, id);
  });
}

Status World::set_time_factor(InstanceId id, float factor) noexcept {
  return detail::guarded("World::set_time_factor", [&]() -> Status {
    const auto found = detail::find_instance(*impl_, id, Driver::kMixer, "World::set_time_factor");
    if (!found.ok()) return found.error();
    if (!std::isfinite(factor)) return bad_value("World::set_time_factor", id, "factor", factor, "a finite factor");
    return detail::to_api_status((*found)->mixer->set_time_factor(factor));
  });
}

Result<Matrix3x4> World::bone_transform(InstanceId id, std::size_t bone) const noexcept {
  return detail::guarded("World::bone_transform", [&]() -> Result<Matrix3x4> {
    const auto found = detail::find_character(*impl_, id, "World::bone_transform");
    if (!found.ok()) return found.error();
    const Impl::Instance& instance = **found;
    if (bone >= instance.skin.size()) {
      return detail::api_error(ErrorCode::kInvalidArgument,
                               "World::bone_transform: instance " + std::to_string(id) + ": bone " +
                                   std::to_string(bone) + ": the character has " +
                                   std::to_string(instance.skin.size()) + " bones");
    }
    if (instance.driver == Driver::kMixer) return detail::to_api(instance.transform * instance.model_pose[bone]);
    // Host-driven: skin = world_from_bone * inverse(bind), so world_from_bone = skin * bind.
    const Affine3& inverse_bind = instance.core->model().skeleton.inverse_bind()[bone];
    return detail::to_api(instance.skin[bone] * inverse(inverse_bind));
  });
}

}  // namespace sinew::api
