#include "game_demo/demo_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>

#include "character/bake.h"
#include "character/framing.h"
#include "content/mannequin/mannequin.h"
#include "raytrace/render/frame_visibility.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::demo {
namespace {

constexpr int kObstacles = 8;


}  // namespace

Affine3 model_to_world(const character::Model& model) {
  const Aabb rest = character::rest_bounds(model);
  const int up = character::up_axis_of(rest);
  const float height = std::max(rest.extent()[up], 1e-6f);
  const float scale = kCharacterHeight / height;
  // Z-up to Y-up: (x, y, z) -> (x, z, -y), so a model facing -Y faces +Z.
  Affine3 axes = Affine3::identity();
  if (up == 2) {
    axes.rows[1] = Vec4(0.0f, 0.0f, 1.0f, 0.0f);
    axes.rows[2] = Vec4(0.0f, -1.0f, 0.0f, 0.0f);
  }
  const Vec3 centre = rest.center();
  const Vec3 feet = axes.transform_point(Vec3(centre.x, centre.y, centre.z)) * scale;
  const float floor = (up == 2 ? rest.lower.z : rest.lower.y) * scale;
  const Affine3 scaled = Affine3::from_trs(Vec3(-feet.x, -floor, -feet.z), Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(scale));
  return scaled * axes;
}

rt::CameraDesc follow_camera_desc(const FollowCamera& camera, const Vec3& target) {
  const Vec3 look_at = target + Vec3(0.0f, 1.1f, 0.0f);
  const Vec3 forward(std::sin(camera.yaw) * std::cos(camera.pitch), -std::sin(camera.pitch),
                     std::cos(camera.yaw) * std::cos(camera.pitch));
  rt::CameraDesc desc;
  desc.eye = look_at - camera.distance * forward;
  desc.eye.y = std::max(desc.eye.y, 0.2f);  // never below the floor
  desc.target = look_at;
  desc.up = Vec3(0.0f, 1.0f, 0.0f);
  desc.fovy_degrees = camera.fovy_degrees;
  return desc;
}

DemoSession::DemoSession(SessionOptions options, character::Model model, World world)
    : options_(std::move(options)), model_(std::move(model)), world_(std::move(world)) {}

DemoSession::~DemoSession() = default;

Expected<std::unique_ptr<DemoSession>> DemoSession::create(const SessionOptions& options, JobSystem& jobs) {
  if (options.model_path.empty()) {
    SINEW_ASSIGN_OR_RETURN(character::Model mannequin, content::make_mannequin());
    return create(options, std::move(mannequin), std::nullopt, jobs);
  }
  // The demo is a game: it loads baked content. Source models (glTF, Cal3D)
  // are the editor's to import and bake.
  if (!character::is_pack_path(options.model_path)) {
    return invalid_argument("--model", options.model_path,
                            "not a content pack (.pack); bake it first: sinew-editor bake " + options.model_path +
                                " -o character.pack");
  }
  SINEW_ASSIGN_OR_RETURN(character::Pack pack, character::Pack::open(options.model_path));
  character::Model model = pack.model();
  // A baked pack brings its fuzzy trees (used in place); a model-only pack
  // is baked in memory like the mannequin.
  std::optional<character::Pack> baked;
  if (pack.has_fuzzy()) baked.emplace(std::move(pack));
  return create(options, std::move(model), std::move(baked), jobs);
}

Expected<std::unique_ptr<DemoSession>> DemoSession::create(const SessionOptions& options, character::Model model,
                                                           JobSystem& jobs) {
  return create(options, std::move(model), std::nullopt, jobs);
}

Expected<std::unique_ptr<DemoSession>> DemoSession::create(const SessionOptions& options, character::Model model,
                                                           std::optional<character::Pack> pack, JobSystem& jobs) {
  if (options.width < 1 || options.height < 1) {
    return invalid_argument("--size", std::to_string(options.width) + "x" + std::to_string(options.height),
                            "must be at least 1x1");
  }
  const Arena arena = Arena::generate(options.seed, kObstacles);
  WorldOptions world_options;
  world_options.characters = options.characters;
  world_options.seed = options.seed;
  world_options.pace_spread = options.pace_spread;
  world_options.arena_half_size = arena.walk_half_size;
  world_options.obstacles = arena.obstacles;
  world_options.model_to_world = model_to_world(model);
  SINEW_ASSIGN_OR_RETURN(World world, World::create(model, world_options));

  std::unique_ptr<DemoSession> session(new DemoSession(options, std::move(model), std::move(world)));
  DemoSession& s = *session;
  s.arena_ = arena;
  const auto bake_start = std::chrono::steady_clock::now();
  rt::FuzzyCharacterView fuzzy;
  if (pack) {
    s.pack_ = std::move(pack);
    fuzzy = s.pack_->fuzzy();
    s.bake_info_.from_pack = true;
  } else {
    SINEW_ASSIGN_OR_RETURN(character::InMemoryBake bake, character::bake_in_memory(s.model_, character::BakeRequest{}, jobs));
    s.fuzzy_ = std::move(bake.fuzzy);
    fuzzy = s.fuzzy_.view();
  }
  const rt::FuzzyBakeStats& stats = s.pack_ ? s.pack_->fuzzy_stats() : s.fuzzy_.stats;
  s.bake_info_.model = options.model_path.empty() ? "mannequin (procedural)" : options.model_path;
  s.bake_info_.triangles = s.model_.mesh.triangle_count();
  s.bake_info_.bones = s.model_.skeleton.joint_count();
  s.bake_info_.pose_samples = stats.sample_count;
  s.bake_info_.bake_ms = ms_since(bake_start);
  s.bake_info_.fuzzy_area_ratio = stats.rest_area > 0.0 ? stats.fuzzy_area / stats.rest_area : 0.0;

  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, s.scene_.add_character(s.model_.mesh, fuzzy));
  for (const rt::StaticMeshDesc& mesh : s.arena_.static_meshes()) {
    // Hits report each as an instance id; nothing to keep.
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t id, s.scene_.add_static_mesh(mesh));
    (void)id;
  }
  for (int i = 0; i < s.world_.character_count(); ++i) {
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t instance, s.scene_.add_instance(character));
    s.instances_.push_back(instance);
  }
  s.settings_.shadows = options.shadows;
  s.settings_.textures = options.textures;
  s.settings_.triangle_test = options.triangle_test;
  s.settings_.light.kind = rt::Light::Kind::kPoint;
  s.settings_.light.position = s.arena_.light_position;
  if (!s.options_.lights.empty()) {
    const std::size_t count = std::min(s.options_.lights.size(), rt::kMaxLights);
    s.settings_.lights = std::span<const rt::Light>(s.options_.lights.data(), count);
  }
  s.settings_.background = Vec3(0.30f, 0.38f, 0.50f);
  s.set_soft_lighting(options.soft);
  s.rgba_.assign(static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height) * 4, 0);
  return session;
}

void DemoSession::set_soft_lighting(const SoftLighting& soft) {
  options_.soft = soft;
  // The lights the frames shade with: the arena's, or those given (which
  // settings_.lights views).
  std::span<rt::Light> lights = options_.lights.empty() ? std::span<rt::Light>(&settings_.light, 1)
                                                         : std::span<rt::Light>(options_.lights);
  apply_soft_lighting(soft, settings_, lights);
}

Expected<FrameReport> DemoSession::frame(float dt, PlayerInput input, const FollowCamera& camera, JobSystem& jobs) {
  input.camera_yaw = camera.yaw;
  {
    ScopedPhase phase(timers_, "animation");
    world_.step(dt, input);
    for (int i = 0; i < world_.character_count(); ++i) {
      SINEW_RETURN_IF_ERROR(scene_.set_bones(instances_[static_cast<std::size_t>(i)], world_.skinning(i)));
    }
  }
  FrameReport report;
  const Vec3 target = world_.character(world_.player()).position;
  SINEW_ASSIGN_OR_RETURN(rt::PinholeCamera cam,
                         rt::PinholeCamera::create(follow_camera_desc(camera, target), options_.width, options_.height));
  camera_ = cam;
  // Characters no camera or shadow ray of this frame can reach are not
  // skinned (docs/RAYTRACE.md, "Culling whole characters").
  rt::FrameOptions frame;
  frame.visibility = rt::frame_visibility(*camera_, settings_);
  SINEW_ASSIGN_OR_RETURN(report.scene, scene_.prepare_frame(frame, jobs, &timers_));
  rt::FrameBuffers buffers;
  buffers.width = options_.width;
  buffers.height = options_.height;
  buffers.color_rgba8 = rgba_;
  SINEW_ASSIGN_OR_RETURN(report.render, renderer_.render(scene_, *camera_, settings_, buffers, jobs, &timers_));
  return report;
}

}  // namespace sinew::demo
