// `sinew-editor render`: import a model and bake it in memory (or load a
// baked content pack and use its trees in place), pose it with one clip, ray
// trace it and write the image, its AOVs and timing stats.
//
//   sinew-editor render MODEL [--clip NAME] [--time SECONDS] [--camera ex,ey,ez,tx,ty,tz,ux,uy,uz,fovy_deg]
//       [--size WxH] --out DIR [--pose-space arbitrary|limits|clips|clip:NAME] [--clips a,b,c]
//       [--samples N] [--seed S] [--shadows on|off] [--textures on|off] [--light x,y,z] [--light-radius R]
//       [--shadow-samples S] [--ao-rays A] [--ao-radius R] [--threads N] [--instances N]
//       [--layout row|grid] [--frames N] [--triangle-test fast|watertight] [--bone-boxes exact|cheap]
//       [--fallback on|off] [--ground on|off] [--limits FILE.json]
//
// Writes DIR/color.png (RGBA8, sRGB), DIR/depth.exr (float32: distance along
// the unit primary ray, +inf on a miss), DIR/triangle_id.exr (uint32,
// 0xFFFFFFFF on a miss) and DIR/stats.json.
//
// The defaults follow character/framing.h (the model's own axes; nothing is
// re-oriented): instance i stands where --layout (row or grid) puts it and
// plays the clip 0.37 s * i later than --time; the ground is a static mesh
// added after the instances, under the whole layout; the camera (no
// --camera) frames all instances' posed bounds at the first frame, and the
// light (no --light) sits above-front-right of them.
// * --clip: default the model's first clip; a model without clips is
//   rendered at its rest pose.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "animation/pose_space.h"
#include "character/bake.h"
#include "character/framing.h"
#include "character/model.h"
#include "editor/import/gltf_importer.h"
#include "raytrace/camera/camera.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/math/aabb.h"
#include "runtime/memory/line_aligned.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::editor {

struct RenderOptions {
  std::string model_path;
  std::string clip;  // name or "#index"; empty: the first clip (rest pose without clips)
  double time_seconds = 0.0;
  std::optional<rt::CameraDesc> camera;  // empty: framed automatically
  int width = 512;
  int height = 512;
  std::string out_dir;  // empty: nothing is written (in-process use)
  // The pose space of an in-memory bake; empty: only the poses the frames
  // render (the default, so a long clip costs its one pose, not its length).
  std::optional<anim::PoseSpaceDesc> pose_space;
  std::string limits_path;         // joint limits JSON, for pose space "limits"
  bool shadows = true;
  bool textures = true;  // textured materials sample their textures (rt::RenderSettings::textures)
  // At most rt::kMaxLights; empty: one white point light placed
  // automatically (character::default_light).
  std::vector<rt::Light> lights;
  // Soft shadows and ambient occlusion (rt::RenderSettings): every point
  // light becomes a sphere of this radius (scene units; 0: a hard point
  // light), shading each hit with shadow_samples rays towards it; ao_rays
  // rays per hit (0: no ambient occlusion) reach ao_radius (scene units;
  // empty: character::default_ao_radius, half the character's height).
  float light_radius = 0.0f;
  int shadow_samples = rt::RenderSettings{}.shadow_samples;
  int ao_rays = 0;
  std::optional<float> ao_radius;
  int threads = 0;  // 0: all cores
  int instances = 1;
  character::Layout layout = character::Layout::kRow;  // --layout: how the instances stand
  int frames = 1;
  rt::TriangleTest triangle_test = rt::TriangleTest::kFast;
  int packet_rays = rt::RenderSettings{}.packet_rays;  // 1, 8, 64, 256 or 512 rays traced together
  bool split_fine_shadows = rt::RenderSettings{}.split_fine_shadow_packets;
  GltfImportOptions gltf;                               // --asset-roots
  rt::BoneBoxMode bone_boxes = rt::BoneBoxMode::kExact;
  bool fallback = true;
  // In-memory bakes only (a pack has its own): pose-space clusters per bone
  // (rt::FuzzyBakeOptions::pose_clusters, 0: none); and whether bones use
  // the clusters a bake or pack has (rt::FrameOptions::pose_clusters).
  std::optional<std::uint32_t> pose_clusters;  // else the bake's size-based default
  rt::BoneTreeKind bone_trees = rt::FuzzyBakeOptions{}.bone_trees;  // in-memory bakes only
  bool use_clusters = true;
  bool ground = true;  // the ground quad under the model (--ground off: characters alone)
  // Called with one line per step (import, bake, frames, write); null: quiet.
  std::function<void(std::string_view)> progress;
  bool help = false;
};

// Parses the arguments after "render". Errors name the flag and the value;
// they are usage errors (exit code 2).
Expected<RenderOptions> parse_render_options(const std::vector<std::string>& args);
std::string render_usage();

struct RenderStatsSummary {
  std::size_t triangles = 0;
  std::size_t bones = 0;
  std::uint32_t pose_samples = 0;
  double fps = 0.0;
  double median_frame_ms = 0.0;
  std::uint64_t primary_rays = 0;  // last frame
  std::uint64_t shadow_rays = 0;   // last frame: hard and area lights'
  std::uint64_t ao_rays = 0;       // last frame
  rt::TraversalCounters primary_work;  // last frame
  rt::TraversalCounters shadow_work;   // last frame
  rt::TraversalCounters ao_work;       // last frame
  // Last frame: each kind of ray's share of the render's wall time
  // (rt::RenderStats).
  double trace_primary_ms = 0.0;
  double trace_shadow_ms = 0.0;
  double trace_ao_ms = 0.0;
  std::size_t escaped_checks = 0;  // last frame
  std::size_t escaped_triangles = 0;
  std::size_t total_escaped_checks = 0;  // over all frames
  std::size_t total_escaped_triangles = 0;
  std::uint32_t clusters = 0;            // the bake's or pack's pose-space clusters, all bones
  std::size_t cluster_bones = 0;         // last frame: bones on a cluster's tree
  std::size_t total_cluster_misses = 0;  // over all frames: bones whose cluster a vertex left
};

// Everything the last frame produced, for tests and callers in-process.
struct RenderOutputs {
  int width = 0;
  int height = 0;
  // Line-aligned, as the renderer stores them fastest.
  LineAlignedVector<std::uint8_t> color_rgba8;
  LineAlignedVector<float> depth;
  LineAlignedVector<std::uint32_t> triangle_id;
  LineAlignedVector<std::uint32_t> instance_id;
  rt::CameraDesc camera;   // the camera used (given or framed)
  std::vector<rt::Light> lights;  // the lights used
  float ao_radius = 0.0f;          // the ambient occlusion reach used (given or derived)
  std::string clip_name;   // empty: rest pose
  double last_frame_seconds = 0.0;  // playback time of instance 0 in the written frame
  std::vector<Affine3> instance_placements;  // per instance: model -> world
  rt::StaticMeshDesc ground;                 // world space
  std::uint32_t ground_instance_id = 0;      // Hit::instance_id of the ground (kInvalidId: none)
  PhaseTimers timers;                        // one sample per phase per frame
  RenderStatsSummary stats;
  std::string stats_json;  // what stats.json holds
};


// Runs the whole command in-process. Errors (user errors, exit code 1) name
// the file, the field and the value.
Expected<RenderOutputs> render_model(const RenderOptions& options);

// The subcommand: arguments after "render". Returns the exit code: 0
// success, 1 user error, 2 usage error; one message on `err` on failure.
int run_render(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sinew::editor
