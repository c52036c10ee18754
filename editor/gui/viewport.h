// Viewport: the editor's ray-traced view of one character on a ground quad:
// the scene, the camera, the render and the overlays. No GL: it produces
// the RGBA8 image the window shows, so it also runs headless in tests.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "character/model.h"
#include "editor/gui/overlays.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"

namespace sinew {
class JobSystem;
class PhaseTimers;
}  // namespace sinew

namespace sinew::editor::gui {

struct ViewportFrame {
  rt::FrameStats scene;
  rt::RenderStats render;
  std::size_t escaped_pixels = 0;  // painted by the escapes overlay
};

class Viewport {
 public:
  // (Re)builds the scene over `model` (mesh) and `fuzzy`; both must outlive
  // the viewport or the next reset. Keeps the camera unless `reframe`.
  Status reset(const character::Model& model, const rt::FuzzyCharacterView& fuzzy, bool reframe);
  void resize(int width, int height);

  // Poses the character, renders and draws the overlay into image().
  Expected<ViewportFrame> render(std::span<const Affine3> skinning, JobSystem& jobs, PhaseTimers* timers);

  // Orbits the camera about its target: yaw about the model's up axis,
  // pitch about the camera's right axis (kept away from the poles).
  void orbit(float yaw_radians, float pitch_radians);
  // Frames the current pose with default_camera on the next render.
  void request_reframe() { reframe_ = true; }

  Overlay overlay = Overlay::kNone;
  std::uint32_t bone = 0;  // for the boxes overlay
  // Soft shadows and ambient occlusion are in here too: shadow_samples,
  // ao_rays, and ao_radius, which a newly loaded model sets to
  // character::default_ao_radius (the Lights panel edits them).
  rt::RenderSettings settings;
  rt::FrameOptions frame_options;
  // The lights the view shades with (1 to rt::kMaxLights; the Lights panel
  // edits them). Empty until a model is framed, which places one point
  // light above and in front of it (character::default_light).
  std::vector<rt::Light> lights;

  // The loaded character's height (character::character_height): what the
  // Lights panel's lengths are scaled by.
  float character_height() const { return character_height_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const rt::CameraDesc& camera() const { return camera_; }
  void set_camera(const rt::CameraDesc& camera) { camera_ = camera; reframe_ = false; }
  std::span<const std::uint8_t> image() const { return image_; }          // with the overlay
  std::span<const std::uint8_t> raw_image() const { return raw_; }        // as rendered
  std::span<const std::uint32_t> triangle_ids() const { return triangle_id_; }
  std::span<const std::uint32_t> instance_ids() const { return instance_id_; }
  std::uint32_t character_instance() const { return instance_; }
  const rt::Scene* scene() const { return scene_.get(); }

 private:
  void apply_overlay(std::span<const Affine3> skinning, ViewportFrame& frame);

  const character::Model* model_ = nullptr;
  rt::FuzzyCharacterView fuzzy_;
  std::unique_ptr<rt::Scene> scene_;
  std::uint32_t instance_ = 0;
  int up_ = 1;
  float character_height_ = 1.0f;
  std::vector<std::uint32_t> heat_;
  rt::CameraDesc camera_;
  bool reframe_ = true;
  int width_ = 640;
  int height_ = 480;
  std::vector<std::uint8_t> raw_;
  std::vector<std::uint8_t> image_;
  std::vector<std::uint32_t> triangle_id_;
  std::vector<std::uint32_t> instance_id_;
  rt::Renderer renderer_;
};

}  // namespace sinew::editor::gui
