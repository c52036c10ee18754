#include "editor/cli/render_command.h"
#include "editor/cli/shown_text.h"

#include <array>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "animation/joint_limits.h"
#include "animation/pose.h"
#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "editor/cli/import_limit_flags.h"
#include "editor/import/model_loader.h"
#include "raytrace/render/frame_visibility.h"
#include "raytrace/render/renderer.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "runtime/image/image_io.h"
#include "runtime/io/atomic_file.h"
#include "runtime/jobs/job_system.h"
#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#endif

namespace sinew::editor {
namespace {

constexpr double kFramesPerSecond = 30.0;
constexpr int kMaxImageSide = 16384;
// The largest light radius and ambient occlusion reach taken, in scene
// units: far beyond any scene the tools frame, small enough that squares
// of it stay finite in float.
constexpr double kMaxLightingLength = 1e6;

const char* const kProgram = "sinew-editor render";

// The command's options, declared in the order --help lists them.
struct RenderFlags {
  explicit RenderFlags(cli::CommandLine& l)
      : model(l.positionals("MODEL", "a glTF (.gltf/.glb) or Cal3D (.cfg) model, or a content pack (.pack)", 1)),
        out(l.option("--out", "DIR", "output folder (created if missing; required)")),
        clip(l.option("--clip", "NAME|#I", "the clip, by name or index (default: the first; rest pose without clips)")),
        time(l.option("--time", "SECONDS", "playback time, looping (default 0)")),
        camera(l.option("--camera", "ex,ey,ez,tx,ty,tz,ux,uy,uz,fovy_deg",
                        "eye, target, up, vertical field of view (default: frames the\n"
                        "posed model from the front, +Z for Y-up models, -Y for Z-up)")),
        size(l.option("--size", "WxH", "image size (default 512x512)")),
        pose_space(l.option("--pose-space", "MODE",
                            "arbitrary|limits|clips|clip:NAME of an in-memory bake (default:\n"
                            "only the poses rendered; with --clips, --samples or --seed alone:\n"
                            "clips, every key and every 1/30 s of every clip)")),
        clips(l.option("--clips", "a,b,c", "the clips of --pose-space clips (default: all)")),
        samples(l.option("--samples", "N", "pose samples (random modes: default 1000; clip modes: 0 = all)")),
        seed(l.option("--seed", "S", "seed of the random pose spaces (default 1)")),
        limits(l.option("--limits", "FILE.json", "joint limits, required by --pose-space limits")),
        shadows(l.option("--shadows", "on|off", "shadow rays (default on)")),
        textures(l.option("--textures", "on|off", "textured materials show their textures (default on)")),
        light(l.repeated_option("--light", "X,Y,Z|point:X,Y,Z|dir:X,Y,Z[:R,G,B]",
                                "a point light at X,Y,Z or a directional light towards X,Y,Z, with\n"
                                "its linear colour (default 1,1,1); up to 8 (default: one point\n"
                                "light above-front of the model)")),
        light_radius(l.option("--light-radius", "R",
                              "every point light becomes a sphere of radius R casting soft shadows\n"
                              "(scene units; default 0: hard point lights)")),
        shadow_samples(l.option("--shadow-samples", "S",
                                "shadow rays per hit towards each sphere light (1-256, default 4)")),
        ao_rays(l.option("--ao-rays", "A", "ambient occlusion rays per hit (0-256; default 0: none)")),
        ao_radius(l.option("--ao-radius", "R",
                           "how far ambient occlusion rays reach (scene units; default half\n"
                           "the character's height)")),
        threads(l.option("--threads", "N", "worker threads (default 0: all cores)")),
        instances(l.option("--instances", "N", "copies of the model, copy i 0.37 s * i later (default 1)")),
        layout(l.option("--layout", "row|grid",
                        "row: copies side by side along +X; grid: ceil(sqrt(N)) columns along +X,\n"
                        "rows away from the default camera (default row)")),
        frames(l.option("--frames", "N", "frames rendered at 30 fps from --time; the last is written (default 1)")),
        triangle_test(l.option("--triangle-test", "fast|watertight", "ray-triangle test (default fast)")),
        packet_rays(l.option("--packet-rays", "1|8|64|256|512",
                             "rays traced together: single rays, 4x2, 8x8, 16x16 or 32x16 pixels\n"
                             "(default 256)")),
        split_fine_shadows(l.option("--split-fine-shadows", "on|off",
                                    "shadow rays of regions on pixel-sized triangles as 8x8-pixel\n"
                                    "packets (default on)")),
        asset_roots(l.option("--asset-roots", "A:B",
                             "more folders a glTF file's buffers may be read from (by default\n"
                             "only its own folder and below)")),
        bone_boxes(l.option("--bone-boxes", "exact|cheap", "per-frame bone boxes (default exact)")),
        fallback(l.option("--fallback", "on|off",
                          "exact rendering of triangles outside their fuzzy boxes (default on)")),
        ground(l.option("--ground", "on|off", "the ground quad under the model (default on)")),
        pose_clusters(l.option("--pose-clusters", "K",
                               "pose-space clusters per bone in the bake, each a tighter tree\n"
                               "(0-64; default 16 from 25,000 triangles, else 0: none;\n"
                               "in-memory bakes, a pack has its own)")),
        clusters(l.option("--clusters", "on|off", "bones use the clusters the bake or pack has (default on)")),
        bone_trees(l.option("--bone-trees", "kd|bvh",
                            "the bake's bone trees (default bvh; in-memory bakes, a pack has its own)")),
        import_limits(l) {}

  const std::vector<std::string>& model;
  const std::optional<std::string>& out;
  const std::optional<std::string>& clip;
  const std::optional<std::string>& time;
  const std::optional<std::string>& camera;
  const std::optional<std::string>& size;
  const std::optional<std::string>& pose_space;
  const std::optional<std::string>& clips;
  const std::optional<std::string>& samples;
  const std::optional<std::string>& seed;
  const std::optional<std::string>& limits;
  const std::optional<std::string>& shadows;
  const std::optional<std::string>& textures;
  const std::vector<std::string>& light;
  const std::optional<std::string>& light_radius;
  const std::optional<std::string>& shadow_samples;
  const std::optional<std::string>& ao_rays;
  const std::optional<std::string>& ao_radius;
  const std::optional<std::string>& threads;
  const std::optional<std::string>& instances;
  const std::optional<std::string>& layout;
  const std::optional<std::string>& frames;
  const std::optional<std::string>& triangle_test;
  const std::optional<std::string>& packet_rays;
  const std::optional<std::string>& split_fine_shadows;
  const std::optional<std::string>& asset_roots;
  const std::optional<std::string>& bone_boxes;
  const std::optional<std::string>& fallback;
  const std::optional<std::string>& ground;
  const std::optional<std::string>& pose_clusters;
  const std::optional<std::string>& clusters;
  const std::optional<std::string>& bone_trees;
  ImportLimitFlags import_limits;
};

// The command line of `render`, before RenderFlags declares its options.
std::unique_ptr<cli::CommandLine> render_command_line() {
  auto line = std::make_unique<cli::CommandLine>(
      kProgram,
      "Imports a glTF (.gltf/.glb) or Cal3D (.cfg) model and bakes it in memory, or loads a\n"
      "content pack (.pack) and uses its baked trees in place (the --pose-space options then\n"
      "do not apply); poses it with one clip and ray traces it. Writes DIR/color.png,\n"
      "DIR/depth.exr, DIR/triangle_id.exr and DIR/stats.json.\n");
  line->footer(
      "The model's up axis is the larger of its rest bounds' Y and Z extents; a ground quad lies\n"
      "under the rest bounds on that axis (unless --ground off).\n");
  return line;
}

// --- option parsing -------------------------------------------------------

Status parse_pose_space(const RenderFlags& f, RenderOptions& o) {
  if (!f.pose_space && !f.clips && !f.samples && !f.seed && !f.limits) return {};  // the rendered poses only
  anim::PoseSpaceDesc& space = o.pose_space.emplace(character::default_pose_space());
  if (const std::optional<std::string>& text = f.pose_space) {
    std::string mode_name = *text;
    std::string clip_name;
    if (const std::size_t colon = text->find(':'); colon != std::string::npos) {
      mode_name = text->substr(0, colon);
      clip_name = text->substr(colon + 1);
    }
    const auto mode = anim::parse_pose_space_mode(mode_name);
    const bool clip_mode = mode.ok() && *mode == anim::PoseSpaceMode::kClip;
    if (!mode.ok() || clip_mode == clip_name.empty()) {
      return invalid_argument("--pose-space", *text, "expected arbitrary, limits, clips or clip:NAME");
    }
    if (*mode == anim::PoseSpaceMode::kArbitrary || *mode == anim::PoseSpaceMode::kLimits) {
      space = anim::PoseSpaceDesc{};  // random poses: 1000 samples, seed 1
      space.mode = *mode;
    } else {
      space.mode = *mode;  // keeps character::default_pose_space()'s every key + 1/30 s
      if (clip_mode) space.clips = {clip_name};
    }
  }
  const anim::PoseSpaceMode mode = space.mode;
  const bool random = mode == anim::PoseSpaceMode::kArbitrary || mode == anim::PoseSpaceMode::kLimits;
  if (const std::optional<std::string>& text = f.clips) {
    if (mode != anim::PoseSpaceMode::kClips) {
      return invalid_argument("--clips", *text, "applies to --pose-space clips only");
    }
    SINEW_ASSIGN_OR_RETURN(space.clips, cli::parse_list("--clips", *text));
  }
  if (const std::optional<std::string>& text = f.samples) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n,
                           cli::parse_int("--samples", *text, random ? 1 : 0, anim::kMaxPoseSamples));
    space.samples = static_cast<int>(n);
  }
  if (const std::optional<std::string>& text = f.seed) {
    SINEW_ASSIGN_OR_RETURN(space.seed, cli::parse_uint64("--seed", *text));
  }
  if (const std::optional<std::string>& text = f.limits) {
    if (mode != anim::PoseSpaceMode::kLimits) {
      return invalid_argument("--limits", *text, "applies to --pose-space limits only");
    }
    o.limits_path = *text;
  } else if (mode == anim::PoseSpaceMode::kLimits) {
    return invalid_argument("--pose-space", "limits", "needs --limits FILE.json (the joint limits to sample within)");
  }
  return {};
}

Status parse_view(const RenderFlags& f, RenderOptions& o) {
  if (const std::optional<std::string>& text = f.camera) {
    SINEW_ASSIGN_OR_RETURN(const std::vector<float> v, cli::parse_floats("--camera", *text, 10));
    rt::CameraDesc desc{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9]};
    // The camera's own checks (eye == target, up along the view, fovy range)
    // are usage errors too: report them against the flag.
    const auto camera = rt::PinholeCamera::create(desc, 1, 1);
    if (!camera.ok()) {
      const Status& s = camera.status();
      return invalid_argument("--camera", *text,
                              std::string(s.field()) + " = " + std::string(s.value()) + ": " + std::string(s.detail()));
    }
    o.camera = desc;
  }
  if (f.light.size() > rt::kMaxLights) {
    return invalid_argument("--light", f.light.back(), "at most " + std::to_string(rt::kMaxLights) + " lights");
  }
  for (const std::string& text : f.light) {
    SINEW_ASSIGN_OR_RETURN(const cli::LightOption light, cli::parse_light("--light", text));
    o.lights.push_back(character::light_from_option(light));
  }
  if (const std::optional<std::string>& text = f.size) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--size", *text, kMaxImageSide));
    o.width = size.width;
    o.height = size.height;
  }
  return {};
}

// Soft shadows and ambient occlusion; after parse_view, which reads the
// lights --light-radius applies to.
Status parse_lighting(const RenderFlags& f, RenderOptions& o) {
  if (const std::optional<std::string>& text = f.light_radius) {
    SINEW_ASSIGN_OR_RETURN(const double r, cli::parse_double("--light-radius", *text, 0.0, kMaxLightingLength));
    const bool any_point = o.lights.empty() || std::any_of(o.lights.begin(), o.lights.end(), [](const rt::Light& l) {
                             return l.kind == rt::Light::Kind::kPoint;
                           });
    if (r > 0.0 && !any_point) {
      return invalid_argument("--light-radius", *text,
                              "applies to point lights, and every --light is directional");
    }
    o.light_radius = static_cast<float>(r);
  }
  if (const std::optional<std::string>& text = f.shadow_samples) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--shadow-samples", *text, 1, rt::kMaxSamples));
    o.shadow_samples = static_cast<int>(n);
  }
  if (const std::optional<std::string>& text = f.ao_rays) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--ao-rays", *text, 0, rt::kMaxSamples));
    o.ao_rays = static_cast<int>(n);
  }
  if (const std::optional<std::string>& text = f.ao_radius) {
    SINEW_ASSIGN_OR_RETURN(const double r, cli::parse_double("--ao-radius", *text, 0.0, kMaxLightingLength));
    // A ray of length 0 finds nothing: the renderer refuses it, so say so here.
    if (!(r > 0.0)) return invalid_argument("--ao-radius", *text, "expected a length above 0");
    o.ao_radius = static_cast<float>(r);
  }
  return {};
}

Status parse_run(const RenderFlags& f, RenderOptions& o) {
  if (const std::optional<std::string>& text = f.clip) {
    if (text->empty()) return invalid_argument("--clip", "", "expected a clip name or #index");
    o.clip = *text;
  }
  if (const std::optional<std::string>& text = f.time) {
    SINEW_ASSIGN_OR_RETURN(o.time_seconds, cli::parse_double("--time", *text, 0.0, 1e6));
  }
  if (const std::optional<std::string>& text = f.out) o.out_dir = *text;
  if (const std::optional<std::string>& text = f.shadows) {
    SINEW_ASSIGN_OR_RETURN(o.shadows, cli::parse_on_off("--shadows", *text));
  }
  if (const std::optional<std::string>& text = f.textures) {
    SINEW_ASSIGN_OR_RETURN(o.textures, cli::parse_on_off("--textures", *text));
  }
  if (const std::optional<std::string>& text = f.fallback) {
    SINEW_ASSIGN_OR_RETURN(o.fallback, cli::parse_on_off("--fallback", *text));
  }
  if (const std::optional<std::string>& text = f.split_fine_shadows) {
    SINEW_ASSIGN_OR_RETURN(o.split_fine_shadows, cli::parse_on_off("--split-fine-shadows", *text));
  }
  if (const std::optional<std::string>& text = f.pose_clusters) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t k, cli::parse_int("--pose-clusters", *text, 0, rt::kMaxPoseClusters));
    o.pose_clusters = static_cast<std::uint32_t>(k);
  }
  if (const std::optional<std::string>& text = f.clusters) {
    SINEW_ASSIGN_OR_RETURN(o.use_clusters, cli::parse_on_off("--clusters", *text));
  }
  if (const std::optional<std::string>& text = f.bone_trees) {
    SINEW_ASSIGN_OR_RETURN(const int c, cli::parse_choice("--bone-trees", *text, {"kd", "bvh"}));
    o.bone_trees = c == 0 ? rt::BoneTreeKind::kKdTree : rt::BoneTreeKind::kBvh;
  }
  if (const std::optional<std::string>& text = f.layout) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--layout", *text, {"row", "grid"}));
    o.layout = static_cast<character::Layout>(i);
  }
  if (const std::optional<std::string>& text = f.ground) {
    SINEW_ASSIGN_OR_RETURN(o.ground, cli::parse_on_off("--ground", *text));
  }
  if (const std::optional<std::string>& text = f.triangle_test) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--triangle-test", *text, {"fast", "watertight"}));
    o.triangle_test = i == 0 ? rt::TriangleTest::kFast : rt::TriangleTest::kWatertight;
  }
  if (const std::optional<std::string>& text = f.asset_roots) {
    SINEW_ASSIGN_OR_RETURN(o.gltf.asset_roots, cli::parse_folder_list("--asset-roots", *text));
  }
  SINEW_RETURN_IF_ERROR(f.import_limits.apply(o.gltf.limits));
  if (const std::optional<std::string>& text = f.packet_rays) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--packet-rays", *text, {"1", "8", "64", "256", "512"}));
    o.packet_rays = std::array<int, 5>{1, 8, 64, 256, 512}[static_cast<std::size_t>(i)];
  }
  if (const std::optional<std::string>& text = f.bone_boxes) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--bone-boxes", *text, {"exact", "cheap"}));
    o.bone_boxes = i == 0 ? rt::BoneBoxMode::kExact : rt::BoneBoxMode::kCheap;
  }
  if (const std::optional<std::string>& text = f.threads) {
    SINEW_ASSIGN_OR_RETURN(o.threads, cli::parse_threads("--threads", *text));
  }
  const auto int_flag = [](const char* flag, const std::optional<std::string>& text, std::int64_t lo,
                           std::int64_t hi, int& target) -> Status {
    if (text) {
      SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int(flag, *text, lo, hi));
      target = static_cast<int>(n);
    }
    return {};
  };
  SINEW_RETURN_IF_ERROR(int_flag("--instances", f.instances, 1, 256, o.instances));
  SINEW_RETURN_IF_ERROR(int_flag("--frames", f.frames, 1, 100000, o.frames));
  return {};
}

// --- model, pose and scene --------------------------------------------------

// The instance's skinning matrices at playback time `seconds`: the clip
// alone at weight 1 (looping), or the rest pose when there is no clip.
Expected<std::vector<Affine3>> pose_instance(const character::Model& model, const anim::Clip* clip, double seconds,
                                             const Affine3& placement) {
  if (clip == nullptr) return character::rest_skinning(model, placement);
  return character::clip_skinning(model, *clip, seconds, placement);
}

// The skinning matrices of every pose the frames draw (each instance at its
// time offset, in model space): an in-memory bake without a pose space
// samples these and nothing else.
Expected<std::vector<Affine3>> rendered_poses(const character::Model& model, const anim::Clip* clip,
                                              const RenderOptions& options) {
  std::vector<Affine3> poses;
  for (int f = 0; f < options.frames; ++f) {
    for (int i = 0; i < options.instances; ++i) {
      const double seconds = options.time_seconds + f / kFramesPerSecond + character::instance_time_offset(i);
      SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> pose, pose_instance(model, clip, seconds, Affine3::identity()));
      poses.insert(poses.end(), pose.begin(), pose.end());
    }
  }
  return poses;
}

std::string pose_space_name(const RenderOptions& options) {
  return options.pose_space ? std::string(anim::pose_space_mode_name(options.pose_space->mode)) : "rendered poses";
}

Expected<const anim::Clip*> resolve_clip(const character::Model& model, const RenderOptions& options) {
  if (options.clip.empty()) return model.clips.empty() ? nullptr : &model.clips.front();
  if (const anim::Clip* clip = model.find_clip(options.clip)) return clip;
  std::string names;
  for (const anim::Clip& c : model.clips) names += (names.empty() ? "" : ", ") + c.name();
  return make_error(ErrorCode::kNotFound, options.model_path, "clip", "'" + options.clip + "'",
                    "no such clip (clips: " + (names.empty() ? std::string("none") : names) + ")");
}




// --- stats ----------------------------------------------------------------

struct FrameRecord {
  double total_ms = 0.0;
  rt::FrameStats frame;
  rt::RenderStats render;
};

Expected<std::string> stats_document(const RenderOptions& options, const character::Model& model,
                                     const character::InMemoryBake& bake, const RenderOutputs& outputs) {
  const nlohmann::ordered_json phases = nlohmann::ordered_json::parse(outputs.timers.json(), nullptr, false);
  if (phases.is_discarded()) {
    return make_error(ErrorCode::kInternal, "stats.json", "phases", "", "PhaseTimers::json() is not valid JSON");
  }
  const rt::FuzzyBakeStats& b = bake.fuzzy.stats;
  const RenderStatsSummary& s = outputs.stats;
  nlohmann::ordered_json doc;
  doc["model"] = shown(options.model_path);
  doc["clip"] = shown(outputs.clip_name);
  doc["time"] = options.time_seconds;
  doc["triangles"] = model.mesh.triangle_count();
  doc["bones"] = model.skeleton.joint_count();
  doc["instances"] = options.instances;
  doc["layout"] = character::kLayoutNames[static_cast<int>(options.layout)];
  doc["frames"] = options.frames;
  doc["size"] = {options.width, options.height};
  doc["samples"] = b.sample_count;
  doc["pose_space"] = pose_space_name(options);
  doc["bake"] = {{"sampling_ms", b.sampling_ms},
                 {"assignment_ms", b.assignment_ms},
                 {"build_ms", b.build_ms},
                 {"fuzzy_area", b.fuzzy_area},
                 {"rest_area", b.rest_area},
                 {"mean_items_per_leaf", b.mean_items_per_leaf},
                 {"max_depth", b.max_depth},
                 {"node_count", b.node_count},
                 {"pose_sampling_ms", bake.pose_sampling_ms}};
  doc["phases"] = phases;
  doc["frame_ms"] = {{"median_ms", s.median_frame_ms}};
  doc["lighting"] = {{"light_radius", options.light_radius},
                     {"shadow_samples", options.shadow_samples},
                     {"ao_rays", options.ao_rays},
                     {"ao_radius", outputs.ao_radius}};
  doc["rays"] = {{"primary", s.primary_rays}, {"shadow", s.shadow_rays}, {"ao", s.ao_rays}};
  const auto work = [](const rt::TraversalCounters& c) {
    return nlohmann::json{{"rays", c.rays},
                          {"node_visits", c.node_visits},
                          {"object_visits", c.object_visits},
                          {"triangle_tests", c.triangle_tests}};
  };
  doc["work"] = {{"primary", work(s.primary_work)}, {"shadow", work(s.shadow_work)}, {"ao", work(s.ao_work)}};
  doc["escapes"] = {{"escaped_checks", s.escaped_checks},
                    {"escaped_triangles", s.escaped_triangles},
                    {"total_escaped_checks", s.total_escaped_checks},
                    {"total_escaped_triangles", s.total_escaped_triangles}};
  doc["clusters"] = {{"clusters", s.clusters},
                     {"cluster_bones", s.cluster_bones},
                     {"total_cluster_misses", s.total_cluster_misses}};
  doc["fps"] = s.fps;
  return doc.dump(2) + "\n";
}

Status write_outputs(const std::string& dir, const RenderOutputs& o) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return make_error(ErrorCode::kIoError, dir, "--out", dir, "cannot create the folder: " + ec.message());
  const std::filesystem::path base(dir);
  SINEW_RETURN_IF_ERROR(write_png((base / "color.png").string(), o.width, o.height, 4, o.color_rgba8));
  SINEW_RETURN_IF_ERROR(write_exr((base / "depth.exr").string(), o.width, o.height, 1, std::span<const float>(o.depth)));
  SINEW_RETURN_IF_ERROR(write_exr((base / "triangle_id.exr").string(), o.width, o.height, 1,
                                  std::span<const std::uint32_t>(o.triangle_id)));
  return write_file_atomic((base / "stats.json").string(), o.stats_json);
}

void report(const RenderOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

}  // namespace

// --- the command --------------------------------------------------------------

std::string render_usage() {
  const auto line = render_command_line();
  const RenderFlags flags(*line);
  return line->help();
}

Expected<RenderOptions> parse_render_options(const std::vector<std::string>& args) {
  const auto line = render_command_line();
  const RenderFlags flags(*line);
  SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, line->parse(args));
  RenderOptions o;
  if (result == cli::ParseResult::kHelp) {
    o.help = true;
    return o;
  }
  if (flags.model.empty()) return invalid_argument("MODEL", "", "missing: the model file to render");
  o.model_path = flags.model.front();
  SINEW_RETURN_IF_ERROR(parse_run(flags, o));
  SINEW_RETURN_IF_ERROR(parse_view(flags, o));
  SINEW_RETURN_IF_ERROR(parse_lighting(flags, o));
  SINEW_RETURN_IF_ERROR(parse_pose_space(flags, o));
  if (o.out_dir.empty()) return invalid_argument("--out", "", "missing: the output folder is required");
  return o;
}

Expected<RenderOutputs> render_model(const RenderOptions& options) {
  if (options.width < 1 || options.height < 1 || options.instances < 1 || options.frames < 1) {
    return invalid_argument("options", std::to_string(options.width) + "x" + std::to_string(options.height),
                            "size, instances and frames must be at least 1");
  }
  // A baked pack renders from its own fuzzy trees, in place; any other
  // model (or a model-only pack) is baked in memory first.
  std::optional<character::Pack> pack;
  character::InMemoryBake bake;
  JobSystem jobs(options.threads);
  if (character::is_pack_path(options.model_path)) {
    report(options, "loading " + options.model_path);
    SINEW_ASSIGN_OR_RETURN(character::Pack loaded, character::Pack::open(options.model_path));
    pack.emplace(std::move(loaded));
  }
  character::Model imported;
  if (!pack) {
    report(options, "importing " + options.model_path);
    SINEW_ASSIGN_OR_RETURN(imported, load_model(options.model_path, options.gltf));
    for (const std::string& warning : imported.warnings) report(options, "warning: " + warning);
  }
  // Packs were checked on load, imported models are by the bake below
  // (character::check_renderable): the one check every consumer shares.
  const character::Model& model = pack ? pack->model() : imported;
  SINEW_ASSIGN_OR_RETURN(const anim::Clip* clip, resolve_clip(model, options));

  if (!pack || !pack->has_fuzzy()) {
    character::BakeRequest request;
    if (options.pose_space) {
      request.pose_space = *options.pose_space;
    } else {
      SINEW_ASSIGN_OR_RETURN(request.poses, rendered_poses(model, clip, options));
    }
    request.fuzzy.pose_clusters = options.pose_clusters.value_or(0);
    request.fuzzy.fine_mesh_clusters = !options.pose_clusters.has_value();
    request.fuzzy.bone_trees = options.bone_trees;
    if (!options.limits_path.empty()) {
      SINEW_ASSIGN_OR_RETURN(request.limits, anim::load_joint_limits(options.limits_path, model.skeleton));
    }
    report(options, "baking (" + pose_space_name(options) + " pose space)");
    SINEW_ASSIGN_OR_RETURN(bake, character::bake_in_memory(model, request, jobs));
  }
  const rt::FuzzyCharacterView fuzzy = pack && pack->has_fuzzy() ? pack->fuzzy() : bake.fuzzy.view();
  if (pack && pack->has_fuzzy()) bake.fuzzy.stats = pack->fuzzy_stats();  // reported in stats.json

  RenderOutputs out;
  out.width = options.width;
  out.height = options.height;
  out.clip_name = clip != nullptr ? clip->name() : "";
  const Aabb rest = character::rest_bounds(model);
  const int up = character::up_axis_of(rest);

  // Scene: the instances first (ids 0..n-1), then the ground.
  rt::Scene scene;
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene.add_character(model.mesh, fuzzy));
  std::vector<std::uint32_t> instance_ids;
  for (int i = 0; i < options.instances; ++i) {
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t id, scene.add_instance(character));
    instance_ids.push_back(id);
    out.instance_placements.push_back(character::instance_placement(rest, i, options.instances, options.layout));
  }
  out.ground_instance_id = kInvalidId;
  if (options.ground) {
    out.ground = character::ground_plane_for(rest, options.instances, options.layout);
    SINEW_ASSIGN_OR_RETURN(out.ground_instance_id, scene.add_static_mesh(out.ground));
  }

  rt::FrameOptions frame_options;
  frame_options.bone_boxes = options.bone_boxes;
  frame_options.fallback = options.fallback;
  frame_options.pose_clusters = options.use_clusters;
  rt::RenderSettings settings;
  settings.triangle_test = options.triangle_test;
  settings.packet_rays = options.packet_rays;
  settings.split_fine_shadow_packets = options.split_fine_shadows;
  settings.shadows = options.shadows;
  settings.textures = options.textures;
  settings.shadow_samples = options.shadow_samples;
  settings.ao_rays = options.ao_rays;
  out.ao_radius = options.ao_radius.value_or(character::default_ao_radius(rest));
  settings.ao_radius = out.ao_radius;

  const std::size_t pixels = static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height);
  out.color_rgba8.assign(4 * pixels, 0);
  out.depth.assign(pixels, 0.0f);
  out.triangle_id.assign(pixels, 0);
  out.instance_id.assign(pixels, 0);
  rt::FrameBuffers buffers;
  buffers.width = options.width;
  buffers.height = options.height;
  buffers.color_rgba8 = out.color_rgba8;
  buffers.depth = out.depth;
  buffers.triangle_id = out.triangle_id;
  buffers.instance_id = out.instance_id;

  report(options, "rendering " + std::to_string(options.frames) + " frame(s) at " + std::to_string(options.width) +
                      "x" + std::to_string(options.height));
  rt::Renderer renderer;
  std::optional<rt::PinholeCamera> camera;
  std::vector<double> frame_ms;
  std::vector<std::vector<Affine3>> bones(instance_ids.size());
  RenderStatsSummary& stats = out.stats;
  for (int f = 0; f < options.frames; ++f) {
    const double seconds = options.time_seconds + f / kFramesPerSecond;
    PhaseTimers frame_timers;
    {
      ScopedPhase animation(frame_timers, "animation");
      for (std::size_t i = 0; i < instance_ids.size(); ++i) {
        const int index = static_cast<int>(i);
        SINEW_ASSIGN_OR_RETURN(bones[i], pose_instance(model, clip, seconds + character::instance_time_offset(index),
                                                       out.instance_placements[i]));
        SINEW_RETURN_IF_ERROR(scene.set_bones(instance_ids[i], bones[i]));
      }
    }
    // The first frame frames the view on every posed instance; later frames
    // skin only the instances the camera's and the lights' rays can reach.
    if (camera) frame_options.visibility = rt::frame_visibility(*camera, settings);
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats frame, scene.prepare_frame(frame_options, jobs, &frame_timers));
    if (!camera) {
      // Framed once, on the first frame's pose, so every frame shares one view.
      const Aabb posed = character::posed_bounds(scene);
      out.camera = options.camera ? *options.camera : character::default_camera(posed, up, options.width, options.height);
      out.lights = options.lights;
      if (out.lights.empty()) {
        out.lights.emplace_back();
        out.lights.back().position = character::default_light(posed, up);
      }
      for (rt::Light& light : out.lights) {
        if (light.kind == rt::Light::Kind::kPoint) light.radius = options.light_radius;
      }
      settings.lights = out.lights;
      SINEW_ASSIGN_OR_RETURN(camera, rt::PinholeCamera::create(out.camera, options.width, options.height));
    }
    SINEW_ASSIGN_OR_RETURN(const rt::RenderStats rendered,
                           renderer.render(scene, *camera, settings, buffers, jobs, &frame_timers));

    double total = 0.0;
    for (const PhaseSummary& phase : frame_timers.summarize()) {
      const double ms = phase.mean_ms * static_cast<double>(phase.samples);
      out.timers.record(phase.name, ms);
      total += ms;
    }
    frame_ms.push_back(total);
    stats.primary_rays = rendered.primary_rays;
    stats.shadow_rays = rendered.shadow_rays;
    stats.ao_rays = rendered.ao_rays;
    stats.primary_work = rendered.primary;
    stats.shadow_work = rendered.shadow;
    stats.ao_work = rendered.ao;
    stats.trace_primary_ms = rendered.trace_primary_ms;
    stats.trace_shadow_ms = rendered.trace_shadow_ms;
    stats.trace_ao_ms = rendered.trace_ao_ms;
    stats.escaped_checks = frame.escaped_checks;
    stats.escaped_triangles = frame.escaped_triangles;
    stats.total_escaped_checks += frame.escaped_checks;
    stats.total_escaped_triangles += frame.escaped_triangles;
    stats.cluster_bones = frame.cluster_bones;
    stats.total_cluster_misses += frame.cluster_misses;
    out.last_frame_seconds = seconds;
  }
  stats.triangles = model.mesh.triangle_count();
  stats.bones = model.skeleton.joint_count();
  stats.pose_samples = bake.fuzzy.stats.sample_count;
  stats.clusters = static_cast<std::uint32_t>(fuzzy.clusters.size());
  stats.median_frame_ms = median_of(frame_ms);
  stats.fps = stats.median_frame_ms > 0.0 ? 1000.0 / stats.median_frame_ms : 0.0;
  SINEW_ASSIGN_OR_RETURN(out.stats_json, stats_document(options, model, bake, out));

  if (!options.out_dir.empty()) {
    report(options, "writing " + options.out_dir);
    SINEW_RETURN_IF_ERROR(write_outputs(options.out_dir, out));
  }
  return out;
}

namespace {

void print_summary(const RenderOptions& options, const RenderOutputs& o, std::ostream& out) {
  const RenderStatsSummary& s = o.stats;
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(2);
  text << shown(options.model_path) << ": " << s.triangles << " triangles, " << s.bones << " bones, " << options.instances
       << (options.instances == 1 ? " instance" : " instances") << ", clip "
       << (o.clip_name.empty() ? std::string("(rest pose)") : "'" + shown(o.clip_name) + "'") << ", " << s.pose_samples
       << " pose samples\n";
  text << o.width << "x" << o.height << ", " << options.frames << (options.frames == 1 ? " frame" : " frames")
       << ": " << s.fps << " fps (median frame " << s.median_frame_ms << " ms)\n";
  for (const PhaseSummary& phase : o.timers.summarize()) {
    text << "  " << phase.name << std::string(phase.name.size() < 14 ? 14 - phase.name.size() : 1, ' ')
         << phase.median_ms << " ms\n";
  }
  const auto per_ray = [&](const char* name, const rt::TraversalCounters& c) {
    const double n = c.rays > 0 ? static_cast<double>(c.rays) : 1.0;
    text << "  " << name << " work per ray: " << static_cast<double>(c.node_visits) / n << " node visits, "
         << static_cast<double>(c.object_visits) / n << " objects, " << static_cast<double>(c.triangle_tests) / n
         << " triangle tests\n";
  };
  if (options.light_radius > 0.0f) {
    text << "soft shadows: point lights of radius " << options.light_radius << ", " << options.shadow_samples
         << " shadow samples per hit\n";
  }
  if (options.ao_rays > 0) {
    text << "ambient occlusion: " << options.ao_rays << " rays per hit, radius " << o.ao_radius << "\n";
  }
  // Each kind's count with its share of the last frame's render time.
  text << "rays (last frame): " << s.primary_rays << " primary in " << s.trace_primary_ms << " ms, " << s.shadow_rays
       << " shadow in " << s.trace_shadow_ms << " ms";
  if (options.ao_rays > 0) text << ", " << s.ao_rays << " ambient occlusion in " << s.trace_ao_ms << " ms";
  text << "\n";
  per_ray("primary", s.primary_work);
  if (s.shadow_work.rays > 0) per_ray("shadow", s.shadow_work);
  if (s.ao_work.rays > 0) per_ray("ambient occlusion", s.ao_work);
  text << "escapes (last frame): " << s.escaped_checks << " checks, " << s.escaped_triangles
       << " triangles; over all frames: " << s.total_escaped_checks << " checks, " << s.total_escaped_triangles
       << " triangles\n";
  if (s.clusters > 0) {
    text << "pose-space clusters: " << s.clusters << ", " << s.cluster_bones
         << " bones on a cluster's tree (last frame), " << s.total_cluster_misses
         << " bones back on their full tree over all frames\n";
  }
  text << "wrote " << shown(options.out_dir) << "/{color.png,depth.exr,triangle_id.exr,stats.json}\n";
  out << text.str();
}

}  // namespace

int run_render(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  auto options = parse_render_options(args);
  if (!options.ok()) {
    return cli::usage_error(kProgram, options.status(), err);
  }
  if (options->help) {
    out << render_usage();
    return 0;
  }
  // Progress lines only for a person watching a terminal.
  if (&out == &std::cout && ::isatty(STDOUT_FILENO) == 1) {
    options->progress = [&out](std::string_view line) { out << line << "..." << std::endl; };
  }
  const auto outputs = render_model(*options);
  if (!outputs.ok()) {
    err << "sinew-editor: " << outputs.status().message() << "\n";
    return 1;
  }
  print_summary(*options, *outputs, out);
  return 0;
}

}  // namespace sinew::editor
