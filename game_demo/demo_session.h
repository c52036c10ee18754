// DemoSession: everything one run of the demo owns — the character model
// and its in-memory fuzzy bake, the arena, the game world, the ray-traced
// scene (arena static mesh + one instance per character) and the renderer's
// output — and one frame of the game loop:
//
//   animation (world step, bone matrices) -> skinning -> boxes -> fallback
//   -> top level -> trace primary -> trace shadow -> shade
//
// each a phase in timers(). The windowed and the headless runs and the
// tests all drive the same session; only where input comes from and where
// the pixels go differ.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "character/model.h"
#include "character/pack.h"
#include "game_demo/arena.h"
#include "game_demo/soft_lighting.h"
#include "game_demo/world.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"
#include "runtime/memory/line_aligned.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::demo {

struct SessionOptions {
  std::string model_path;  // a content pack (.pack); empty: the procedural mannequin
  int characters = 6;
  std::uint32_t seed = 1;
  float pace_spread = 0.0f;  // WorldOptions::pace_spread
  int width = 1024;
  int height = 1024;
  bool shadows = true;
  bool textures = true;  // textured materials show their textures (RenderSettings::textures)
  rt::TriangleTest triangle_test = rt::TriangleTest::kFast;
  std::vector<rt::Light> lights;  // at most rt::kMaxLights; empty: the arena's point light
  SoftLighting soft;              // soft shadows and ambient occlusion (off by default)
};

// The third-person camera's free parameters; it follows the player.
struct FollowCamera {
  float yaw = 0.0f;     // radians about +Y; 0 looks along +Z
  float pitch = 0.42f;  // radians below the horizon
  float distance = 7.0f;
  float fovy_degrees = 55.0f;
};

// What one frame did, beyond the phase times.
struct FrameReport {
  rt::FrameStats scene;
  rt::RenderStats render;
};

// Model facts shown by the HUD and written to timings.json.
struct BakeInfo {
  std::string model;
  std::size_t triangles = 0;
  std::size_t bones = 0;
  std::uint32_t pose_samples = 0;
  double bake_ms = 0.0;            // the in-memory bake, or loading the pack
  double fuzzy_area_ratio = 0.0;  // fuzzy area / rest area
  bool from_pack = false;         // the fuzzy trees came from a content pack
};

class DemoSession {
 public:
  // Loads the character (a content pack, the mannequin when
  // options.model_path is empty), bakes it over all its clips unless the
  // pack brings its fuzzy trees, builds the arena and the world. Source
  // models (glTF, Cal3D) are refused with the editor command that bakes
  // them. Errors name the file and what was wrong.
  static Expected<std::unique_ptr<DemoSession>> create(const SessionOptions& options, JobSystem& jobs);
  // The same for a model the caller already has (a benchmark importing a
  // source model with the editor's importers), baked in memory;
  // options.model_path only names it.
  static Expected<std::unique_ptr<DemoSession>> create(const SessionOptions& options, character::Model model,
                                                       JobSystem& jobs);

  // Steps the world by dt with `input` (input.camera_yaw is taken from
  // `camera`), poses the characters and renders into rgba().
  Expected<FrameReport> frame(float dt, PlayerInput input, const FollowCamera& camera, JobSystem& jobs);

  std::span<const std::uint8_t> rgba() const { return rgba_; }
  int width() const { return options_.width; }
  int height() const { return options_.height; }
  PhaseTimers& timers() { return timers_; }
  const World& world() const { return world_; }
  const BakeInfo& bake_info() const { return bake_info_; }
  const Arena& arena() const { return arena_; }
  // Render settings the HUD may change between frames.
  rt::RenderSettings& render_settings() { return settings_; }
  // Soft shadows and ambient occlusion from the next frame on: the
  // settings, and the radius of every point light (the HUD's toggles).
  void set_soft_lighting(const SoftLighting& soft);
  const SoftLighting& soft_lighting() const { return options_.soft; }
  // The camera of the last frame (call after frame()).
  const rt::PinholeCamera& camera() const { return *camera_; }

  DemoSession(const DemoSession&) = delete;
  DemoSession& operator=(const DemoSession&) = delete;
  ~DemoSession();

 private:
  DemoSession(SessionOptions options, character::Model model, World world);
  static Expected<std::unique_ptr<DemoSession>> create(const SessionOptions& options, character::Model model,
                                                       std::optional<character::Pack> pack, JobSystem& jobs);

  SessionOptions options_;
  // The model and the bake are referenced by the scene: they stay put
  // (the session is heap-allocated and never moves).
  character::Model model_;
  rt::FuzzyCharacterData fuzzy_;               // an in-memory bake, or
  std::optional<character::Pack> pack_;  // a baked pack's trees, in place
  Arena arena_;
  World world_;
  rt::Scene scene_;
  std::vector<std::uint32_t> instances_;
  rt::Renderer renderer_;
  rt::RenderSettings settings_;
  std::optional<rt::PinholeCamera> camera_;  // set by the first frame
  LineAlignedVector<std::uint8_t> rgba_;  // line-aligned, as the renderer stores it fastest
  PhaseTimers timers_;
  BakeInfo bake_info_;
};

// Model space -> demo world: the rest pose's up axis (Y or Z, the larger
// extent) turned to +Y, scaled to 1.8 m tall, feet on y = 0, centred on the
// origin in x and z. Models are assumed to face +Z (Y-up) or -Y (Z-up).
Affine3 model_to_world(const character::Model& model);

// The follow camera for a character standing at `target` (its feet).
rt::CameraDesc follow_camera_desc(const FollowCamera& camera, const Vec3& target);

}  // namespace sinew::demo
