#include "editor/gui/viewport.h"

#include <algorithm>
#include <cmath>

#include "character/framing.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::editor::gui {

Status Viewport::reset(const character::Model& model, const rt::FuzzyCharacterView& fuzzy, bool reframe) {
  auto scene = std::make_unique<rt::Scene>();
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene->add_character(model.mesh, fuzzy));
  SINEW_ASSIGN_OR_RETURN(instance_, scene->add_instance(character));
  const Aabb rest = character::rest_bounds(model);
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t ground, scene->add_static_mesh(character::ground_plane_for(rest, 1)));
  (void)ground;
  up_ = character::up_axis_of(rest);
  character_height_ = character::character_height(rest);
  scene_ = std::move(scene);
  model_ = &model;
  fuzzy_ = fuzzy;
  heat_ = leaf_heat(fuzzy, model.mesh.triangle_count());
  bone = std::min<std::uint32_t>(bone, fuzzy.bone_count > 0 ? fuzzy.bone_count - 1 : 0);
  if (reframe) {
    reframe_ = true;
    lights.clear();  // a new model gets its own default light
    settings.ao_radius = character::default_ao_radius(rest);  // and an occlusion reach of its size
  }
  return Status{};
}

void Viewport::resize(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = std::max(1, width);
  height_ = std::max(1, height);
  reframe_ = true;
}

Expected<ViewportFrame> Viewport::render(std::span<const Affine3> skinning, JobSystem& jobs, PhaseTimers* timers) {
  if (!scene_) return make_error(ErrorCode::kInvalidArgument, "", "viewport", "empty", "no model loaded");
  ViewportFrame frame;
  SINEW_RETURN_IF_ERROR(scene_->set_bones(instance_, skinning));
  SINEW_ASSIGN_OR_RETURN(frame.scene, scene_->prepare_frame(frame_options, jobs, timers));
  if (reframe_) {
    const Aabb posed = character::posed_bounds(*scene_);
    camera_ = character::default_camera(posed, up_, width_, height_);
    if (lights.empty()) {
      lights.emplace_back();
      lights.back().position = character::default_light(posed, up_);
    }
    reframe_ = false;
  }
  if (lights.size() > rt::kMaxLights) lights.resize(rt::kMaxLights);
  settings.lights = lights;
  SINEW_ASSIGN_OR_RETURN(const rt::PinholeCamera camera, rt::PinholeCamera::create(camera_, width_, height_));
  const std::size_t pixels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  raw_.resize(4 * pixels);
  triangle_id_.resize(pixels);
  instance_id_.resize(pixels);
  rt::FrameBuffers buffers;
  buffers.width = width_;
  buffers.height = height_;
  buffers.color_rgba8 = raw_;
  buffers.triangle_id = triangle_id_;
  buffers.instance_id = instance_id_;
  SINEW_ASSIGN_OR_RETURN(frame.render, renderer_.render(*scene_, camera, settings, buffers, jobs, timers));
  PhaseTimers unused;
  {
    ScopedPhase phase(timers != nullptr ? *timers : unused, "overlay");
    image_ = raw_;
    apply_overlay(skinning, frame);
  }
  return frame;
}

void Viewport::apply_overlay(std::span<const Affine3> skinning, ViewportFrame& frame) {
  const ImageRef image{width_, height_, image_};
  switch (overlay) {
    case Overlay::kNone: break;
    case Overlay::kBoxes:
      if (bone < skinning.size()) {
        draw_bone_boxes(image, Projection(camera_, width_, height_), fuzzy_, bone, skinning[bone]);
      }
      break;
    case Overlay::kHeat: apply_heat(image, triangle_id_, instance_id_, instance_, heat_); break;
    case Overlay::kEscapes: {
      const rt::InstanceFrame& state = scene_->instances()[0];
      frame.escaped_pixels = apply_escapes(image, triangle_id_, instance_id_, instance_, state.escaped_triangles,
                                           model_->mesh.triangle_count());
      break;
    }
  }
}

namespace {

Vec3 rotate_about(const Vec3& v, const Vec3& axis, float angle) {
  // Rodrigues' rotation formula (axis unit length).
  const float c = std::cos(angle);
  const float s = std::sin(angle);
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0f - c);
}

}  // namespace

void Viewport::orbit(float yaw_radians, float pitch_radians) {
  if (reframe_) return;  // nothing framed yet to orbit
  Vec3 up(0.0f);
  up[up_] = 1.0f;
  Vec3 offset = camera_.eye - camera_.target;
  offset = rotate_about(offset, up, -yaw_radians);
  const Vec3 right = glm::normalize(glm::cross(-offset, up));
  const Vec3 pitched = rotate_about(offset, right, pitch_radians);
  // Refuse pitches that would bring the view direction near the up axis
  // (the camera's basis degenerates there).
  const float cos_to_up = glm::dot(glm::normalize(pitched), up);
  if (std::abs(cos_to_up) < 0.98f) offset = pitched;
  camera_.eye = camera_.target + offset;
  camera_.up = up;
  reframe_ = false;
}

}  // namespace sinew::editor::gui
