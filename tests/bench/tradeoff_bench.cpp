#include "tests/bench/tradeoff_bench.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "animation/joint_limits.h"
#include "animation/pose_space.h"
#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/brute_force_gate.h"
#include "tests/bench/table_numbers.h"
#include "tests/bench/walk_measure.h"
#include "tests/support/brute_force.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

constexpr double kKneeHoleFraction = 1e-4;
constexpr int kWalkGateStride = 7;
// The bake's random modes use seed 1 (PoseSpaceDesc's default); the held-out
// poses come from another stream so no held-out pose is a sampled one.
constexpr std::uint64_t kHeldOutSeed = 0x9e3779b97f4a7c15ull;
constexpr std::uint64_t kCrackSeed = 2006;


// --- options -------------------------------------------------------------------

struct Options {
  std::string model = "cally";
  std::vector<int> samples{4, 8, 16, 32, 62, 124, 250, 500, 1000};
  std::vector<std::string> modes{"arbitrary", "limits", "clips", "clip"};
  std::vector<double> paddings{0.0, 0.01, 0.05};
  int held_out = 500;
  int width = 512;
  int height = 512;
  int hole_width = 96;
  int hole_height = 96;
  int frames = 11;  // walk frames per fps measurement
  int threads = 2;
  int crack_subdivisions = 4;
  // The pose-space clusters' side study: the model subdivided this many
  // times (clusters only pay on fine meshes), baked with each K.
  std::vector<int> cluster_counts{0, 4, 8, 16, 32};
  int cluster_level = 3;
  bool quick = false;
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  std::string markdown_path;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      quick_flag("samples 4,16,62,250, modes arbitrary,clips, padding 0,0.05, 256x256,\n"
                 "32x32 hole image, 3 walk frames"),
      {"--model", "M", "cally (default; the mannequin when Cally is absent) or mannequin"},
      {"--samples", "LIST", "pose samples per bake (default 4,8,16,32,62,124,250,500,1000)"},
      {"--modes", "LIST", "arbitrary,limits,clips,clip (default all four; clip = the walk alone)"},
      {"--padding", "LIST", "fuzzy box padding, a fraction of the rest-pose box diagonal\n(default 0,0.01,0.05)"},
      {"--held-out", "N", "held-out poses per mode for escapes and holes (default 500)"},
      {"--clusters", "LIST", "pose-space clusters per bone for the clusters' study (default 0,4,8,16,32;\n"
                             "none: skip it)"},
      {"--cluster-level", "L", "subdivision levels of the model in the clusters' study (default 3)"},
      size_flag("512x512"),
      threads_flag("2"),
      shared_flag(),
      json_flag(),
      markdown_flag(),
  };
}

const char* const kDescription = "speed against accuracy: samples, pose spaces, padding, held-out escapes and holes,\nfallback cost, fast vs watertight, exact vs cheap boxes\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  namespace cli = sinew::cli;
  if (parsed.has("--quick")) {  // explicit flags below still override
    o.quick = true;
    o.samples = {4, 16, 62, 250};
    o.modes = {"arbitrary", "clips"};
    o.paddings = {0.0, 0.05};
    o.width = o.height = 256;
    o.hole_width = o.hole_height = 32;
    o.frames = 3;
    o.crack_subdivisions = 3;
    o.cluster_counts = {0, 16};
    o.cluster_level = 2;
  }
  if (const auto text = parsed.value("--model")) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--model", *text, {"cally", "mannequin"}));
    o.model = i == 0 ? "cally" : "mannequin";
  }
  if (const auto text = parsed.value("--samples")) {
    SINEW_ASSIGN_OR_RETURN(o.samples, parse_int_list("--samples", *text, 1, anim::kMaxPoseSamples));
    std::sort(o.samples.begin(), o.samples.end());
    o.samples.erase(std::unique(o.samples.begin(), o.samples.end()), o.samples.end());
  }
  if (const auto text = parsed.value("--modes")) {
    SINEW_ASSIGN_OR_RETURN(o.modes, cli::parse_list("--modes", *text));
    for (const std::string& mode : o.modes) {
      if (!anim::parse_pose_space_mode(mode).ok()) {
        return invalid_argument("--modes", mode, "unknown mode (expected arbitrary, limits, clips or clip)");
      }
    }
  }
  if (const auto text = parsed.value("--padding")) {
    SINEW_ASSIGN_OR_RETURN(const std::vector<std::string> items, cli::parse_list("--padding", *text));
    o.paddings.clear();
    for (const std::string& item : items) {
      SINEW_ASSIGN_OR_RETURN(const double p, cli::parse_double("--padding", item, 0.0, 10.0));
      o.paddings.push_back(p);
    }
    std::sort(o.paddings.begin(), o.paddings.end());
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--held-out", 1, 1000000, o.held_out));
  if (const auto text = parsed.value("--clusters")) {
    if (*text == "none") {
      o.cluster_counts.clear();
    } else {
      SINEW_ASSIGN_OR_RETURN(o.cluster_counts,
                             parse_int_list("--clusters", *text, 0, static_cast<int>(rt::kMaxPoseClusters)));
    }
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--cluster-level", 0, editor::kMaxSubdivisionLevels, o.cluster_level));
  SINEW_RETURN_IF_ERROR(parsed.read_size(16384, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  SINEW_RETURN_IF_ERROR(parsed.read("--markdown", o.markdown_path));
  return {};
}

// --- model ---------------------------------------------------------------------

struct BenchModel {
  std::string name;
  character::Model model;
  std::size_t walk_clip = 0;
  int up = 1;
};

// Where the lead keeps Cally's joint limits: content/limits/cally.json of
// the source tree this file belongs to.
std::string cally_limits_path() {
#ifdef SINEW_SOURCE_DIR
  return std::string(SINEW_SOURCE_DIR) + "/content/limits/cally.json";
#else
  return (std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "content" / "limits" /
          "cally.json")
      .string();
#endif
}

// --- pose-space modes ----------------------------------------------------------

struct ModeSpec {
  std::string name;
  anim::PoseSpaceMode mode = anim::PoseSpaceMode::kArbitrary;
  std::vector<std::string> clips;       // kClip: {"walk"}
  std::vector<anim::JointLimit> limits;  // kLimits
  int available = 0;  // clip modes: distinct poses the space has (0: unbounded)
};

// The distinct clip times kClips/kClip would visit with 30 Hz sampling.
int clip_space_size(const character::Model& model, const ModeSpec& spec) {
  std::size_t n = 0;
  for (const anim::Clip& clip : model.clips) {
    if (spec.mode == anim::PoseSpaceMode::kClip && clip.name() != spec.clips.front()) continue;
    n += anim::clip_sample_times(clip, true).size();
  }
  return static_cast<int>(n);
}

anim::PoseSpaceDesc bake_space(const ModeSpec& spec, int samples) {
  anim::PoseSpaceDesc desc;
  desc.mode = spec.mode;
  desc.clips = spec.clips;
  if (spec.mode == anim::PoseSpaceMode::kClips || spec.mode == anim::PoseSpaceMode::kClip) {
    desc.every_frame_30hz = true;
    desc.samples = samples >= spec.available ? 0 : samples;  // 0: every time
  } else {
    desc.samples = samples;
  }
  return desc;
}

// The held-out poses (model-space skinning matrices, one vector per pose):
// random modes draw from another seed; clip modes take uniform random times
// in [0, duration) of a uniformly chosen clip, which almost never fall on a
// key or a 1/30 s sample.
Expected<std::vector<std::vector<Affine3>>> held_out_poses(const BenchModel& m, const ModeSpec& spec, int count) {
  std::vector<std::vector<Affine3>> poses;
  const std::size_t joints = m.model.skeleton.joint_count();
  if (spec.mode == anim::PoseSpaceMode::kArbitrary || spec.mode == anim::PoseSpaceMode::kLimits) {
    anim::PoseSpaceDesc desc;
    desc.mode = spec.mode;
    desc.samples = count;
    desc.seed = kHeldOutSeed;
    SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> all, character::pose_space_skinning(m.model, desc, spec.limits));
    for (std::size_t p = 0; p + joints <= all.size(); p += joints) {
      poses.emplace_back(all.begin() + static_cast<std::ptrdiff_t>(p),
                         all.begin() + static_cast<std::ptrdiff_t>(p + joints));
    }
    return poses;
  }
  std::vector<const anim::Clip*> clips;
  for (const anim::Clip& clip : m.model.clips) {
    if (spec.mode == anim::PoseSpaceMode::kClip && clip.name() != spec.clips.front()) continue;
    clips.push_back(&clip);
  }
  if (clips.empty()) return invalid_argument("--modes", spec.name, "the model has no clips to sample");
  std::mt19937_64 random(kHeldOutSeed);
  for (int i = 0; i < count; ++i) {
    const anim::Clip& clip = *clips[static_cast<std::size_t>(random() % clips.size())];
    const double t = anim::unit_double(random()) * static_cast<double>(clip.duration());
    SINEW_ASSIGN_OR_RETURN(std::vector<Affine3> bones, character::clip_skinning(m.model, clip, t));
    poses.push_back(std::move(bones));
  }
  return poses;
}

// --- the walk: fps -------------------------------------------------------------

struct WalkResult {
  double frame_ms = 0.0;  // median of prepare_frame + render
  double boxes_ms = 0.0;  // median "boxes" phase
  // Triangle tests per traced ray (primary and shadow) over every frame:
  // the work the fuzzy boxes cost, free of the timing noise of a shared
  // machine (and, tile order fixed, the same on every run).
  double tests_per_ray = 0.0;
  // Triangle tests plus kd-tree node visits per traced ray: the whole
  // deterministic cost the trees leave, the trade plot's speed axis.
  double work_per_ray = 0.0;
  double skinning_ms = 0.0;      // median "skinning" phase (with the escape check)
  double cluster_bones = 0.0;    // mean bones on a pose-space cluster's tree a frame
  double cluster_misses = 0.0;   // mean bones a frame whose cluster a vertex left
  GateResult gate;
};

// The walk (walk_measure.h) at the sweep's size and frame count.
Expected<WalkResult> walk_of(const BenchModel& m, const rt::FuzzyCharacterView& fuzzy, const Options& o,
                             const rt::FrameOptions& frame_options, rt::TriangleTest test, JobSystem& jobs,
                             WalkFraming& framing) {
  WalkRequest request;
  request.frames = o.frames;
  request.width = o.width;
  request.height = o.height;
  request.frame_options = frame_options;
  request.test = test;
  request.gate_stride = kWalkGateStride;
  SINEW_ASSIGN_OR_RETURN(const WalkMeasure walked,
                         measure_walk(m.model, fuzzy, m.model.clips[m.walk_clip], request, jobs, framing));
  WalkResult result;
  result.frame_ms = walked.median_frame_ms();
  result.boxes_ms = walked.phase_ms("boxes");
  result.skinning_ms = walked.phase_ms("skinning");
  const std::uint64_t rays = walked.primary.rays + walked.shadow.rays;
  const std::uint64_t tests = walked.primary.triangle_tests + walked.shadow.triangle_tests;
  const std::uint64_t visits = walked.primary.node_visits + walked.shadow.node_visits;
  result.tests_per_ray = rays > 0 ? static_cast<double>(tests) / static_cast<double>(rays) : 0.0;
  result.work_per_ray = rays > 0 ? static_cast<double>(tests + visits) / static_cast<double>(rays) : 0.0;
  result.cluster_bones = walked.cluster_bones;
  result.cluster_misses = walked.cluster_misses;
  result.gate = walked.gate;
  return result;
}

// --- held-out poses: escapes, holes, fallback cost ------------------------------

// Per mode: the held-out poses and, filled on first use, each pose's camera
// and brute-force reference (computed once, reused by every sample count and
// padding of the mode).
struct ModeState {
  ModeSpec spec;
  std::vector<std::vector<Affine3>> poses;
  std::vector<std::optional<rt::PinholeCamera>> cameras;
  std::vector<std::unique_ptr<BruteForceGate>> references;
  double reference_ms = 0.0;
};

struct HeldOutResult {
  double escaped_fraction = 0.0;  // mean over poses of escaped triangles / triangles
  std::uint64_t pixels_compared = 0;
  std::uint64_t hole_pixels = 0;  // primary hits differing from brute force, fallback off
  std::uint64_t grazes = 0;
  double fallback_ms = 0.0;        // mean "fallback" phase, fallback on
  double frame_off_ms = 0.0;       // mean prepare + primary render, fallback off
  double frame_on_ms = 0.0;        // the same, fallback on
  double hole_fraction() const {
    return pixels_compared ? static_cast<double>(hole_pixels) / static_cast<double>(pixels_compared) : 0.0;
  }
};

Expected<HeldOutResult> measure_held_out(const BenchModel& m, const rt::FuzzyCharacterView& fuzzy, const Options& o,
                                         JobSystem& jobs, ModeState& state) {
  rt::Scene scene;
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene.add_character(m.model.mesh, fuzzy));
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t instance, scene.add_instance(character));
  rt::RenderSettings settings;
  settings.shadows = false;  // holes are a primary-ray question
  rt::FrameOptions off;
  off.fallback = false;
  off.normals = false;
  rt::FrameOptions on = off;
  on.fallback = true;
  PrimaryHitRenderer hits(o.hole_width, o.hole_height);
  const double triangles = static_cast<double>(m.model.mesh.triangle_count());

  HeldOutResult r;
  double escaped_sum = 0.0, fallback_sum = 0.0, off_sum = 0.0, on_sum = 0.0;
  for (std::size_t i = 0; i < state.poses.size(); ++i) {
    SINEW_RETURN_IF_ERROR(scene.set_bones(instance, state.poses[i]));
    const Clock::time_point off_start = Clock::now();
    SINEW_RETURN_IF_ERROR(status_of(scene.prepare_frame(off, jobs)));
    double off_ms = ms_since(off_start);
    if (!state.references[i]) {  // the skinned triangles are the same for every bake
      const Clock::time_point ref_start = Clock::now();
      const Aabb posed = character::posed_bounds(scene);
      SINEW_ASSIGN_OR_RETURN(state.cameras[i],
                             rt::PinholeCamera::create(character::default_camera(posed, m.up, o.hole_width, o.hole_height),
                                                       o.hole_width, o.hole_height));
      state.references[i] = std::make_unique<BruteForceGate>(scene, *state.cameras[i], 1);
      state.reference_ms += ms_since(ref_start);
    }
    const Clock::time_point render_off = Clock::now();
    SINEW_ASSIGN_OR_RETURN(const std::span<const Hit> primary, hits.render(scene, *state.cameras[i], settings, jobs));
    off_ms += ms_since(render_off);
    const GateResult checked = state.references[i]->check(primary);
    r.pixels_compared += checked.checked;
    r.hole_pixels += checked.mismatched;
    r.grazes += checked.grazes;

    PhaseTimers timers;
    const Clock::time_point on_start = Clock::now();
    // Escaped triangles are counted only when the fallback is built: with
    // it off prepare_frame clears the list (escaped_checks stays counted).
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats stats, scene.prepare_frame(on, jobs, &timers));
    escaped_sum += static_cast<double>(stats.escaped_triangles) / triangles;
    SINEW_RETURN_IF_ERROR(status_of(hits.render(scene, *state.cameras[i], settings, jobs)));
    on_sum += ms_since(on_start);
    off_sum += off_ms;
    fallback_sum += phase_median(timers, "fallback");
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, state.poses.size()));
  r.escaped_fraction = escaped_sum / n;
  r.fallback_ms = fallback_sum / n;
  r.frame_off_ms = off_sum / n;
  r.frame_on_ms = on_sum / n;
  return r;
}

// --- one configuration of the sweep --------------------------------------------

struct SweepRow {
  std::string mode;
  int samples = 0;
  int samples_used = 0;
  double padding = 0.0;
  double bake_ms = 0.0;
  std::size_t pack_bytes = 0;
  double fuzzy_area_ratio = 0.0;
  double tris_per_leaf = 0.0;
  double fps = 0.0;
  double tests_per_ray = 0.0;
  double work_per_ray = 0.0;
  GateResult gate;
  HeldOutResult held_out;
};

Expected<std::size_t> pack_size(const BenchModel& m, const ModeSpec& spec, const character::BakeRequest& request,
                                const character::InMemoryBake& bake) {
  character::PackContents contents;
  contents.model = &m.model;
  contents.limits = spec.limits;
  contents.fuzzy = &bake.fuzzy;
  contents.pose_space.desc = request.pose_space;
  contents.pose_space.padding = request.fuzzy.padding;
  contents.provenance.source_name = m.name;
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::byte> bytes, character::serialize_pack(contents));
  return bytes.size();
}

Expected<SweepRow> run_configuration(const BenchModel& m, const Options& o, ModeState& state, int samples,
                                     double padding, JobSystem& jobs, WalkFraming& walk) {
  SweepRow row;
  row.mode = state.spec.name;
  row.samples = samples;
  row.padding = padding;
  character::BakeRequest request;
  request.pose_space = bake_space(state.spec, samples);
  request.limits = state.spec.limits;
  request.fuzzy.padding = static_cast<float>(padding);
  const Clock::time_point bake_start = Clock::now();
  SINEW_ASSIGN_OR_RETURN(const character::InMemoryBake bake, character::bake_in_memory(m.model, request, jobs));
  row.bake_ms = ms_since(bake_start);
  const rt::FuzzyBakeStats& stats = bake.fuzzy.stats;
  row.samples_used = static_cast<int>(stats.sample_count);
  row.fuzzy_area_ratio = stats.rest_area > 0.0 ? stats.fuzzy_area / stats.rest_area : 0.0;
  row.tris_per_leaf = stats.mean_items_per_leaf;
  SINEW_ASSIGN_OR_RETURN(row.pack_bytes, pack_size(m, state.spec, request, bake));

  SINEW_ASSIGN_OR_RETURN(const WalkResult walked, walk_of(m, bake.fuzzy.view(), o, rt::FrameOptions{},
                                                               rt::TriangleTest::kFast, jobs, walk));
  row.fps = walked.frame_ms > 0.0 ? 1000.0 / walked.frame_ms : 0.0;
  row.tests_per_ray = walked.tests_per_ray;
  row.work_per_ray = walked.work_per_ray;
  row.gate = walked.gate;
  if (!row.gate.passed()) return row;  // not reported: its numbers would describe a wrong image
  SINEW_ASSIGN_OR_RETURN(row.held_out, measure_held_out(m, bake.fuzzy.view(), o, jobs, state));
  return row;
}

// --- side studies --------------------------------------------------------------

struct SideRow {
  std::string name;
  double fps = 0.0;
  double boxes_ms = 0.0;
  CrackResult crack;
  GateResult gate;
};

// One K of the pose-space clusters' study.
struct ClusterRow {
  int clusters_per_bone = 0;
  std::uint32_t cluster_count = 0;
  double bake_ms = 0.0;
  std::size_t pack_bytes = 0;
  double fuzzy_area_ratio = 0.0;    // the full trees'
  double cluster_area_ratio = 0.0;  // averaged over each bone's clusters
  WalkResult walk;
  double fps() const { return walk.frame_ms > 0.0 ? 1000.0 / walk.frame_ms : 0.0; }
};

Json cluster_json(const ClusterRow& r) {
  return {{"clusters_per_bone", r.clusters_per_bone}, {"clusters", r.cluster_count},
          {"bake_ms", r.bake_ms},                     {"pack_bytes", r.pack_bytes},
          {"fuzzy_area_ratio", r.fuzzy_area_ratio},   {"cluster_area_ratio", r.cluster_area_ratio},
          {"fps", r.fps()},                           {"tests_per_ray", r.walk.tests_per_ray},
          {"work_per_ray", r.walk.work_per_ray},      {"skinning_ms", r.walk.skinning_ms},
          {"cluster_bones", r.walk.cluster_bones},    {"cluster_misses", r.walk.cluster_misses}};
}

// --- report --------------------------------------------------------------------

std::string padding_text(double padding) { return general(padding); }

void print_sweep_header() {
  std::printf("  %-9s %7s %5s %7s %9s %10s %6s %6s %7s %6s %7s %10s %10s %9s %8s %8s\n", "mode", "samples", "used",
              "padding", "bake ms", "pack bytes", "area", "tri/lf", "fps", "tst/ry", "work/ry", "escaped", "holes",
              "pixels", "fb ms", "fb +ms");
}

void print_sweep_row(const SweepRow& r) {
  if (!r.gate.passed()) {
    std::printf("  %-9s %7d %5d %7s FAILED: first walk frame differs from brute force on %llu of %llu pixels\n",
                r.mode.c_str(), r.samples, r.samples_used, padding_text(r.padding).c_str(),
                static_cast<unsigned long long>(r.gate.mismatched), static_cast<unsigned long long>(r.gate.checked));
    return;
  }
  const HeldOutResult& h = r.held_out;
  std::printf("  %-9s %7d %5d %7s %9.1f %10zu %6.2f %6.2f %7.1f %6.2f %7.2f %10.3e %10.3e %9llu %8.3f %8.3f\n",
              r.mode.c_str(), r.samples, r.samples_used, padding_text(r.padding).c_str(), r.bake_ms, r.pack_bytes,
              r.fuzzy_area_ratio, r.tris_per_leaf, r.fps, r.tests_per_ray, r.work_per_ray, h.escaped_fraction,
              h.hole_fraction(),
              static_cast<unsigned long long>(h.pixels_compared), h.fallback_ms, h.frame_on_ms - h.frame_off_ms);
  std::fflush(stdout);
}

std::vector<KneePoint> knee_points(const std::vector<SweepRow>& rows) {
  std::vector<KneePoint> points;
  for (const SweepRow& r : rows) {
    if (!r.gate.passed()) continue;
    points.push_back({r.mode, r.samples_used, r.padding, r.fps, r.held_out.hole_fraction()});
  }
  return points;
}

Json sweep_json(const SweepRow& r) {
  const HeldOutResult& h = r.held_out;
  return {{"mode", r.mode},
          {"samples", r.samples},
          {"samples_used", r.samples_used},
          {"padding", r.padding},
          {"bake_ms", r.bake_ms},
          {"pack_bytes", r.pack_bytes},
          {"fuzzy_area_ratio", r.fuzzy_area_ratio},
          {"tris_per_leaf", r.tris_per_leaf},
          {"fps", r.fps},
          {"triangle_tests_per_ray", r.tests_per_ray},
          {"work_per_ray", r.work_per_ray},
          {"escaped_fraction", h.escaped_fraction},
          {"hole_fraction", h.hole_fraction()},
          {"hole_pixels", h.hole_pixels},
          {"pixels_compared", h.pixels_compared},
          {"edge_grazes", h.grazes},
          {"fallback_ms", h.fallback_ms},
          {"held_out_frame_ms_fallback_off", h.frame_off_ms},
          {"held_out_frame_ms_fallback_on", h.frame_on_ms},
          {"fallback_frame_diff_ms", h.frame_on_ms - h.frame_off_ms},
          {"gate", {{"checked", r.gate.checked}, {"mismatched", r.gate.mismatched}, {"edge_grazes", r.gate.grazes}}}};
}

struct Report {
  const Options* o = nullptr;
  std::string model;
  std::string command;
  std::string cpu;
  std::string date;
  std::vector<std::string> notes;
  std::vector<SweepRow> rows;
  std::vector<std::pair<std::string, std::optional<KneePoint>>> knees;
  std::vector<SideRow> triangle_tests;
  std::vector<SideRow> bone_boxes;
  std::vector<ClusterRow> clusters;
  std::size_t cluster_triangles = 0;
  std::size_t triangles = 0;
  double wall_s = 0.0;
};

std::string markdown(const Report& rep) {
  const Options& o = *rep.o;
  std::string md;
  const auto line = [&md](const std::string& s) { md += s + "\n"; };
  line("## The speed/accuracy trade");
  line("");
  line("Measured by `" + rep.command + "` on " + rep.cpu + ", " + std::to_string(o.threads) + " threads, " +
       rep.date + " (commit " + git_commit() + "). Numbers are provisional when the machine is shared.");
  line("");
  line("### The sweep: pose-space mode, sample count, padding");
  line("");
  line("Model " + rep.model + " (" + std::to_string(rep.triangles) + " triangles). For every mode, sample count and "
       "padding the character is baked in memory (`bake ms`: `bake_in_memory` wall time on " +
       std::to_string(o.threads) + " threads, pose sampling included); `pack bytes` is the exact size of the character "
       "pack the editor would write (`character::serialize_pack`); `area` is the fuzzy box area over the rest-pose "
       "box area; `fps` is 1000 / the median of prepare_frame + render over " + std::to_string(o.frames) +
       " frames of the walk at 30 Hz, " + std::to_string(o.width) + "x" + std::to_string(o.height) +
       ", fallback on, shadows on, point light, fast triangle test; `tests/ray` is the triangle tests per traced "
       "ray (primary and shadow) over those frames, the speed side of the trade without the timing noise; `work/ray` adds the kd-tree node visits (inner and leaf, every tree) to those tests, the cost the plot draws; the "
       "first frame is checked against brute force (every " + std::to_string(kWalkGateStride) + "th pixel) and a configuration that fails is FAILED and not "
       "reported. Accuracy is measured on " + std::to_string(o.held_out) + " held-out poses per mode that the bake "
       "never sampled: arbitrary/limits draw the same mode with another seed, clips/clip take uniform random times "
       "in [0, duration) of a random clip (the walk for `clip`). `escaped` is the mean fraction of triangles routed "
       "to the fallback (FrameStats::escaped_triangles / triangles). `holes` is, with the fallback off, the fraction "
       "of pixels whose primary hit differs from brute force (tolerances of the brute-force gate: t relative 1e-4, "
       "edge grazes accepted) over a " + std::to_string(o.hole_width) + "x" + std::to_string(o.hole_height) +
       " image framing each posed character, every pixel, the references computed once per mode; `pixels` is the "
       "total compared. `fb ms` is the mean \"fallback\" phase with the fallback on, `fb +ms` the mean difference of "
       "prepare_frame + primary render at the hole size between fallback on and off. Padding is a fraction of the "
       "rest-pose bounding box diagonal added to every vertex box on each side. Clip modes sample every key and every "
       "1/30 s and pick N evenly; `used` is the real pose count, and a count the clips cannot reach is not repeated.");
  line("");
  line("| mode | samples | used | padding | bake ms | pack bytes | area | tri/leaf | fps | tests/ray | work/ray | "
       "escaped | holes | pixels | fb ms | fb +ms |");
  line("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
  for (const SweepRow& r : rep.rows) {
    if (!r.gate.passed()) {
      line("| " + r.mode + " | " + std::to_string(r.samples) + " | " + std::to_string(r.samples_used) + " | " +
           padding_text(r.padding) + " | FAILED | | | | | | | | | | | |");
      continue;
    }
    const HeldOutResult& h = r.held_out;
    line("| " + r.mode + " | " + std::to_string(r.samples) + " | " + std::to_string(r.samples_used) + " | " +
         padding_text(r.padding) + " | " + fixed(r.bake_ms, 1) + " | " + std::to_string(r.pack_bytes) + " | " +
         fixed(r.fuzzy_area_ratio, 2) + " | " + fixed(r.tris_per_leaf, 2) + " | " + fixed(r.fps, 1) + " | " +
         fixed(r.tests_per_ray, 2) + " | " + fixed(r.work_per_ray, 2) + " | " + sci(h.escaped_fraction) + " | " + sci(h.hole_fraction()) + " | " +
         std::to_string(h.pixels_compared) + " | " + fixed(h.fallback_ms, 3) + " | " +
         fixed(h.frame_on_ms - h.frame_off_ms, 3) + " |");
  }
  line("");
  line("### The knee");
  line("");
  line("The knee of a mode's curve is the smallest sample count (poses actually used) whose hole fraction on the "
       "held-out poses, at the smallest padding measured (" + padding_text(o.paddings.front()) + "), is below " +
       general(kKneeHoleFraction) + "; fps is that configuration's. Fewer samples bake faster and trace faster "
       "but leave holes (or fallback work) on poses between the samples; more samples past the knee buy little.");
  line("");
  line("| mode | knee samples | fps | hole fraction |");
  line("|---|---:|---:|---:|");
  for (const auto& [mode, knee] : rep.knees) {
    if (knee) {
      line("| " + mode + " | " + std::to_string(knee->samples_used) + " | " + fixed(knee->fps, 1) + " | " +
           sci(knee->hole_fraction) + " |");
    } else {
      line("| " + mode + " | none below " + general(kKneeHoleFraction) + " | | |");
    }
  }
  line("");
  line("### Fast vs watertight triangle test");
  line("");
  line("fps as in the sweep (the same walk frames, size and settings) on the default bake (every clip, keys and "
       "1/30 s), once per test. The crack test is independent of the model: a closed icosphere (" +
       std::to_string(20 * (1 << (2 * o.crack_subdivisions))) + " triangles, every edge shared by two) of radius 1, "
       "and one ray aimed at every vertex, at every edge's midpoint and at one random point of every edge, from a "
       "random direction at least 17 degrees above the surface, stopped just past its target (t_max 1.001); a ray "
       "that meets no triangle passed through a crack. Every triangle is tested (brute force), so the count is the "
       "triangle test's alone.");
  line("");
  line("| test | fps | crack rays | leaked |");
  line("|---|---:|---:|---:|");
  for (const SideRow& s : rep.triangle_tests) {
    line("| " + s.name + " | " + fixed(s.fps, 1) + " | " + std::to_string(s.crack.rays) + " | " +
         std::to_string(s.crack.leaked) + " |");
  }
  line("");
  line("### Exact vs cheap bone world boxes");
  line("");
  line("The same walk, default bake, fast test; `boxes ms` is the median \"boxes\" phase of prepare_frame.");
  line("");
  line("| bone boxes | boxes ms | fps |");
  line("|---|---:|---:|");
  for (const SideRow& s : rep.bone_boxes) {
    line("| " + s.name + " | " + fixed(s.boxes_ms, 3) + " | " + fixed(s.fps, 1) + " |");
  }
  if (!rep.clusters.empty()) {
    line("");
    line("### Pose-space clusters");
    line("");
    line("Model " + rep.model + " subdivided " + std::to_string(o.cluster_level) + " times (" +
         std::to_string(rep.cluster_triangles) + " triangles), the default bake (every clip, keys and 1/30 s) with K "
         "pose-space clusters per bone (`FuzzyBakeOptions::pose_clusters`, docs/RAYTRACE.md \"Pose-space "
         "clusters\"; 0 = the paper's one tree a bone), the walk measured as in the sweep. `clusters` counts them over "
         "all bones (bones whose triangles never move get none); `area` is the full trees' fuzzy area over the rest "
         "pose's, `cl. area` the same averaged over each bone's clusters (what a frame's trees hold); `skin ms` is the "
         "median skinning phase with the escape check, which reads the clusters' boxes; `on cl.` the bones a frame "
         "on a cluster's tree and `misses` those a frame whose vertex left its cluster (back on the full tree, the "
         "check run again). A cluster changes no image: a bone whose vertices leave its cluster's boxes falls back "
         "to its full tree, so holes and escapes are those of K = 0; K trades pack size and bake time for work per "
         "ray.");
    line("");
    line("| K | clusters | bake ms | pack bytes | area | cl. area | fps | tests/ray | work/ray | skin ms | on cl. | "
         "misses |");
    line("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (const ClusterRow& r : rep.clusters) {
      if (!r.walk.gate.passed()) {
        line("| " + std::to_string(r.clusters_per_bone) + " | FAILED | | | | | | | | | | |");
        continue;
      }
      line("| " + std::to_string(r.clusters_per_bone) + " | " + std::to_string(r.cluster_count) + " | " +
           fixed(r.bake_ms, 0) + " | " + std::to_string(r.pack_bytes) + " | " + fixed(r.fuzzy_area_ratio, 2) + " | " +
           fixed(r.cluster_area_ratio, 2) + " | " + fixed(r.fps(), 1) + " | " + fixed(r.walk.tests_per_ray, 2) +
           " | " + fixed(r.walk.work_per_ray, 2) + " | " + fixed(r.walk.skinning_ms, 2) + " | " +
           fixed(r.walk.cluster_bones, 1) + " | " + fixed(r.walk.cluster_misses, 2) + " |");
    }
  }
  for (const std::string& note : rep.notes) line("\n" + note);
  return md;
}

Json report_json(const Report& rep) {
  const Options& o = *rep.o;
  Json doc;
  doc["model"] = rep.model;
  doc["held_out"] = o.held_out;
  doc["size"] = {o.width, o.height};
  doc["hole_size"] = {o.hole_width, o.hole_height};
  doc["threads"] = o.threads;
  doc["frames"] = o.frames;
  doc["triangles"] = rep.triangles;
  doc["command"] = rep.command;
  doc["sweep"] = Json::array();
  for (const SweepRow& r : rep.rows) {
    if (r.gate.passed()) doc["sweep"].push_back(sweep_json(r));
  }
  doc["failed"] = Json::array();
  for (const SweepRow& r : rep.rows) {
    if (!r.gate.passed()) {
      doc["failed"].push_back({{"mode", r.mode}, {"samples", r.samples}, {"padding", r.padding},
                               {"mismatched", r.gate.mismatched}, {"checked", r.gate.checked}});
    }
  }
  doc["knee_rule"] = "smallest samples_used whose hole_fraction at the smallest padding is below " +
                     general(kKneeHoleFraction);
  doc["knee"] = Json::array();
  for (const auto& [mode, knee] : rep.knees) {
    if (knee) {
      doc["knee"].push_back(
          {{"mode", mode}, {"samples", knee->samples_used}, {"fps", knee->fps}, {"hole_fraction", knee->hole_fraction}});
    } else {
      doc["knee"].push_back({{"mode", mode}, {"samples", nullptr}, {"fps", nullptr}, {"hole_fraction", nullptr}});
    }
  }
  doc["triangle_test"] = Json::array();
  for (const SideRow& s : rep.triangle_tests) {
    doc["triangle_test"].push_back(
        {{"test", s.name}, {"fps", s.fps}, {"crack_rays", s.crack.rays}, {"leaked", s.crack.leaked}});
  }
  doc["bone_boxes"] = Json::array();
  for (const SideRow& s : rep.bone_boxes) {
    doc["bone_boxes"].push_back({{"mode", s.name}, {"boxes_ms", s.boxes_ms}, {"fps", s.fps}});
  }
  doc["cluster_level"] = o.cluster_level;
  doc["cluster_triangles"] = rep.cluster_triangles;
  doc["clusters"] = Json::array();
  for (const ClusterRow& r : rep.clusters) {
    if (r.walk.gate.passed()) doc["clusters"].push_back(cluster_json(r));
  }
  doc["notes"] = rep.notes;
  doc["wall_s"] = rep.wall_s;
  doc["commit"] = git_commit();
  doc["cpu"] = rep.cpu;
  doc["date"] = rep.date;
  return doc;
}

// --- the crack mesh ------------------------------------------------------------

struct Icosphere {
  std::vector<Vec3> positions;  // on the unit sphere around `center`
  std::vector<std::array<std::uint32_t, 3>> triangles;
  Vec3 center{0.0f};
};

// The icosahedron refined `subdivisions` times (each triangle into four,
// midpoints shared through a map so neighbours share their vertices
// exactly), projected onto the unit sphere around `center`.
Icosphere make_icosphere(int subdivisions, const Vec3& center) {
  const float g = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3> unit = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                            {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vec3& v : unit) v = glm::normalize(v);
  std::vector<std::array<std::uint32_t, 3>> tris = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6},
      {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6},  {3, 6, 8},   {3, 8, 9}, {4, 9, 5},  {2, 4, 11},  {6, 2, 10},
      {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      unit.push_back(glm::normalize(unit[a] + unit[b]));
      const auto index = static_cast<std::uint32_t>(unit.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& t : tris) {
      const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    tris = std::move(finer);
  }
  Icosphere sphere;
  sphere.center = center;
  for (const Vec3& v : unit) sphere.positions.push_back(center + v);
  sphere.triangles = std::move(tris);
  return sphere;
}

// A unit direction at least ~17 degrees above the plane whose normal is
// `normal` (cosine >= 0.3 with it): steep enough that the ray crosses the
// surface at its target rather than grazing it.
Vec3 direction_above(const Vec3& normal, std::mt19937_64& random) {
  for (;;) {
    const Quat q = anim::uniform_rotation(anim::unit_double(random()), anim::unit_double(random()),
                                          anim::unit_double(random()));
    const Vec3 d = q * Vec3(0.0f, 0.0f, 1.0f);
    if (glm::dot(d, normal) >= 0.3f) return d;
  }
}

}  // namespace

// --- exposed pieces ------------------------------------------------------------

std::optional<KneePoint> find_knee(const std::vector<KneePoint>& points, const std::string& mode, double threshold) {
  std::optional<double> padding;
  for (const KneePoint& p : points) {
    if (p.mode == mode && (!padding || p.padding < *padding)) padding = p.padding;
  }
  if (!padding) return std::nullopt;
  std::optional<KneePoint> knee;
  for (const KneePoint& p : points) {
    if (p.mode != mode || p.padding != *padding || !(p.hole_fraction < threshold)) continue;
    if (!knee || p.samples_used < knee->samples_used) knee = p;
  }
  return knee;
}

CrackResult crack_test(bool watertight, int subdivisions, std::uint64_t seed) {
  const Icosphere sphere = make_icosphere(subdivisions, Vec3(0.37f, 1.91f, -0.53f));
  std::vector<testing_support::SoupTriangle> soup;
  for (std::uint32_t t = 0; t < sphere.triangles.size(); ++t) {
    const auto& v = sphere.triangles[t];
    soup.push_back({sphere.positions[v[0]], sphere.positions[v[1]], sphere.positions[v[2]], t, 0});
  }
  // Targets: every vertex, and on every edge its midpoint and a random point.
  std::mt19937_64 random(seed);
  std::vector<Vec3> targets(sphere.positions.begin(), sphere.positions.end());
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& t : sphere.triangles) {
    for (std::size_t e = 0; e < 3; ++e) edges.insert(std::minmax(t[e], t[(e + 1) % 3]));
  }
  for (const auto& edge : edges) {
    const Vec3& a = sphere.positions[edge.first];
    const Vec3& b = sphere.positions[edge.second];
    targets.push_back((a + b) * 0.5f);
    targets.push_back(a + anim::unit_float(random()) * (b - a));
  }
  const rt::TriangleTest test = watertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast;
  CrackResult result;
  for (const Vec3& target : targets) {
    const Vec3 normal = glm::normalize(target - sphere.center);
    Ray ray;
    ray.origin = target + 3.0f * direction_above(normal, random);
    ray.direction = target - ray.origin;  // the target at t = 1
    ray.t_max = 1.001f;                   // the far side of the sphere lies beyond t = 1.1
    ++result.rays;
    if (!testing_support::any_hit(soup, ray, test)) ++result.leaked;
  }
  return result;
}

int run_tradeoff_bench(const std::vector<std::string>& args, const std::string& command_line) {
  const Clock::time_point run_start = Clock::now();
  BenchArgs bench_args("tradeoff", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;

  Report rep;
  rep.o = &o;
  rep.command = command_line;
  rep.cpu = cpu_model();
  rep.date = utc_date();
  print_bench_header("tradeoff", command_line, std::to_string(o.threads), rep.cpu, rep.date);

  // The model: Cally, or the mannequin when Cally is absent.
  BenchModel m;
  m.name = o.model;
  {
    std::string note;
    auto loaded = load_model(o.model, o.shared, note);
    if (!loaded.ok()) {
      std::fprintf(stderr, "sinew-bench tradeoff: %s: %s\n", o.model.c_str(), loaded.status().message().c_str());
      return 1;
    }
    if (!loaded->has_value()) {
      rep.notes.push_back(note + "; measured the mannequin instead");
      std::printf("  note: %s\n", rep.notes.back().c_str());
      m.name = "mannequin";
      loaded = load_model("mannequin", o.shared, note);
      if (!loaded.ok() || !loaded->has_value()) {
        std::fprintf(stderr, "sinew-bench tradeoff: mannequin: %s\n",
                     loaded.ok() ? "not made" : loaded.status().message().c_str());
        return 1;
      }
    }
    m.model = std::move(**loaded);
  }
  const auto walk = find_walk_clip(m.model, m.name);
  if (!walk.ok()) {
    std::fprintf(stderr, "sinew-bench tradeoff: %s\n", walk.status().message().c_str());
    return 1;
  }
  m.walk_clip = *walk;
  m.up = character::up_axis_of(character::rest_bounds(m.model));
  rep.model = m.name;
  rep.triangles = m.model.mesh.triangle_count();
  std::printf("  model %s: %zu triangles, %zu bones; walk at %dx%d (%d frames), holes at %dx%d on %d held-out poses\n",
              m.name.c_str(), rep.triangles, m.model.skeleton.joint_count(), o.width, o.height, o.frames,
              o.hole_width, o.hole_height, o.held_out);
  std::fflush(stdout);

  JobSystem jobs(o.threads);
  WalkFraming walk_shared;
  int exit_code = 0;

  // --- the sweep ---
  print_sweep_header();
  for (const std::string& mode_name : o.modes) {
    ModeState state;
    state.spec.name = mode_name;
    state.spec.mode = *anim::parse_pose_space_mode(mode_name);
    if (state.spec.mode == anim::PoseSpaceMode::kClip) state.spec.clips = {m.model.clips[m.walk_clip].name()};
    if (state.spec.mode == anim::PoseSpaceMode::kLimits) {
      if (m.name == "mannequin") {
        state.spec.limits = content::mannequin_joint_limits(m.model.skeleton);
      } else {
        const std::string path = cally_limits_path();
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) {
          rep.notes.push_back("limits mode skipped for " + m.name + ": " + path + " not found");
          std::printf("  note: %s\n", rep.notes.back().c_str());
          continue;
        }
        auto limits = anim::load_joint_limits(path, m.model.skeleton);
        if (!limits.ok()) {
          std::fprintf(stderr, "sinew-bench tradeoff: %s\n", limits.status().message().c_str());
          exit_code = 1;
          continue;
        }
        state.spec.limits = std::move(*limits);
      }
    }
    if (state.spec.mode == anim::PoseSpaceMode::kClips || state.spec.mode == anim::PoseSpaceMode::kClip) {
      state.spec.available = clip_space_size(m.model, state.spec);
    }
    auto poses = held_out_poses(m, state.spec, o.held_out);
    if (!poses.ok()) {
      std::fprintf(stderr, "sinew-bench tradeoff: %s: %s\n", mode_name.c_str(), poses.status().message().c_str());
      exit_code = 1;
      continue;
    }
    state.poses = std::move(*poses);
    state.cameras.resize(state.poses.size());
    state.references.resize(state.poses.size());

    bool reached_all = false;
    for (const int samples : o.samples) {
      if (state.spec.available > 0 && samples >= state.spec.available) {
        if (reached_all) continue;  // the same configuration again
        reached_all = true;
        if (samples != o.samples.back()) {
          rep.notes.push_back(mode_name + ": the clips have " + std::to_string(state.spec.available) +
                              " distinct sample times; sample counts from " + std::to_string(samples) +
                              " up use them all and are measured once");
          std::printf("  note: %s\n", rep.notes.back().c_str());
        }
      }
      for (const double padding : o.paddings) {
        const Clock::time_point start = Clock::now();
        auto row = run_configuration(m, o, state, samples, padding, jobs, walk_shared);
        if (!row.ok()) {
          std::fprintf(stderr, "sinew-bench tradeoff: %s samples %d padding %g: %s\n", mode_name.c_str(), samples,
                       padding, row.status().message().c_str());
          exit_code = 1;
          continue;
        }
        if (!row->gate.passed()) exit_code = 1;
        print_sweep_row(*row);
        std::fprintf(stderr, "  [%.0f s] %s samples %d padding %g done in %.1f s\n", ms_since(run_start) / 1000.0,
                     mode_name.c_str(), samples, padding, ms_since(start) / 1000.0);
        rep.rows.push_back(std::move(*row));
      }
    }
    std::fprintf(stderr, "  %s: brute-force references %.1f s for %zu poses\n", mode_name.c_str(),
                 state.reference_ms / 1000.0, state.poses.size());
  }

  // --- the knee ---
  const std::vector<KneePoint> points = knee_points(rep.rows);
  std::printf("\n  knee (smallest samples whose held-out hole fraction at padding %s is below %g):\n",
              padding_text(o.paddings.front()).c_str(), kKneeHoleFraction);
  for (const std::string& mode_name : o.modes) {
    bool measured = false;
    for (const KneePoint& p : points) measured = measured || p.mode == mode_name;
    if (!measured) continue;
    const std::optional<KneePoint> knee = find_knee(points, mode_name, kKneeHoleFraction);
    rep.knees.emplace_back(mode_name, knee);
    if (knee) {
      std::printf("  %-9s %5d samples, %.1f fps, holes %.2e\n", mode_name.c_str(), knee->samples_used, knee->fps,
                  knee->hole_fraction);
    } else {
      std::printf("  %-9s none below %g\n", mode_name.c_str(), kKneeHoleFraction);
    }
  }

  // --- side studies on the default bake ---
  std::fprintf(stderr, "  [%.0f s] side studies\n", ms_since(run_start) / 1000.0);
  auto bake = character::bake_in_memory(m.model, character::BakeRequest{}, jobs);
  if (!bake.ok()) {
    std::fprintf(stderr, "sinew-bench tradeoff: default bake: %s\n", bake.status().message().c_str());
    return 1;
  }
  const auto side_walk = [&](const std::string& name, rt::TriangleTest test,
                             rt::BoneBoxMode boxes) -> std::optional<SideRow> {
    rt::FrameOptions frame_options;
    frame_options.bone_boxes = boxes;
    auto walked = walk_of(m, bake->fuzzy.view(), o, frame_options, test, jobs, walk_shared);
    if (!walked.ok()) {
      std::fprintf(stderr, "sinew-bench tradeoff: %s: %s\n", name.c_str(), walked.status().message().c_str());
      exit_code = 1;
      return std::nullopt;
    }
    SideRow row;
    row.name = name;
    row.gate = walked->gate;
    row.fps = walked->frame_ms > 0.0 ? 1000.0 / walked->frame_ms : 0.0;
    row.boxes_ms = walked->boxes_ms;
    if (!row.gate.passed()) {
      std::printf("  %s: FAILED (first walk frame differs from brute force on %llu of %llu pixels)\n", name.c_str(),
                  static_cast<unsigned long long>(row.gate.mismatched),
                  static_cast<unsigned long long>(row.gate.checked));
      exit_code = 1;
      return std::nullopt;
    }
    return row;
  };
  std::printf("\n  triangle test (default bake: every clip, keys + 1/30 s; crack test: icosphere of %d triangles)\n",
              20 * (1 << (2 * o.crack_subdivisions)));
  std::printf("  %-10s %7s %10s %7s\n", "test", "fps", "crack rays", "leaked");
  for (const bool watertight : {false, true}) {
    const std::string name = watertight ? "watertight" : "fast";
    auto row = side_walk(name, watertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast,
                         rt::BoneBoxMode::kExact);
    if (!row) continue;
    row->crack = crack_test(watertight, o.crack_subdivisions, kCrackSeed);
    std::printf("  %-10s %7.1f %10llu %7llu\n", name.c_str(), row->fps,
                static_cast<unsigned long long>(row->crack.rays), static_cast<unsigned long long>(row->crack.leaked));
    rep.triangle_tests.push_back(*row);
  }
  std::printf("\n  bone world boxes (default bake, fast test)\n");
  std::printf("  %-10s %9s %7s\n", "boxes", "boxes ms", "fps");
  for (const bool exact : {true, false}) {
    const std::string name = exact ? "exact" : "cheap";
    auto row = side_walk(name, rt::TriangleTest::kFast, exact ? rt::BoneBoxMode::kExact : rt::BoneBoxMode::kCheap);
    if (!row) continue;
    std::printf("  %-10s %9.3f %7.1f\n", name.c_str(), row->boxes_ms, row->fps);
    rep.bone_boxes.push_back(*row);
  }

  // --- pose-space clusters on the subdivided model ---
  if (!o.cluster_counts.empty()) {
    std::fprintf(stderr, "  [%.0f s] pose-space clusters\n", ms_since(run_start) / 1000.0);
    auto finer = editor::subdivide(m.model, o.cluster_level);
    if (!finer.ok()) {
      std::fprintf(stderr, "sinew-bench tradeoff: subdivide: %s\n", finer.status().message().c_str());
      return 1;
    }
    BenchModel fine = m;
    fine.model = std::move(*finer);
    rep.cluster_triangles = fine.model.mesh.triangle_count();
    WalkFraming fine_walk;
    std::printf("\n  pose-space clusters (%s subdivided %d times: %zu triangles; default bake, fast test)\n",
                m.name.c_str(), o.cluster_level, rep.cluster_triangles);
    std::printf("  %4s %8s %8s %11s %7s %8s %7s %7s %8s %7s %6s %6s\n", "K", "clusters", "bake ms", "pack bytes",
                "area", "cl.area", "fps", "tst/ry", "work/ry", "skin ms", "on cl", "misses");
    for (const int k : o.cluster_counts) {
      character::BakeRequest request;
      request.fuzzy.pose_clusters = static_cast<std::uint32_t>(k);
      request.fuzzy.fine_mesh_clusters = false;  // K = 0 is the paper's structure here
      const Clock::time_point bake_start = Clock::now();
      auto bake_k = character::bake_in_memory(fine.model, request, jobs);
      if (!bake_k.ok()) {
        std::fprintf(stderr, "sinew-bench tradeoff: clusters %d: %s\n", k, bake_k.status().message().c_str());
        exit_code = 1;
        continue;
      }
      ClusterRow row;
      row.clusters_per_bone = k;
      row.bake_ms = ms_since(bake_start);
      const rt::FuzzyBakeStats& stats = bake_k->fuzzy.stats;
      row.cluster_count = stats.cluster_count;
      row.fuzzy_area_ratio = stats.rest_area > 0.0 ? stats.fuzzy_area / stats.rest_area : 0.0;
      row.cluster_area_ratio =
          stats.rest_area > 0.0 ? (k > 0 ? stats.cluster_fuzzy_area : stats.fuzzy_area) / stats.rest_area : 0.0;
      auto bytes = pack_size(fine, ModeSpec{}, request, *bake_k);
      auto walked = bytes.ok() ? walk_of(fine, bake_k->fuzzy.view(), o, rt::FrameOptions{},
                                              rt::TriangleTest::kFast, jobs, fine_walk)
                               : Expected<WalkResult>(bytes.status());
      if (!walked.ok()) {
        std::fprintf(stderr, "sinew-bench tradeoff: clusters %d: %s\n", k, walked.status().message().c_str());
        exit_code = 1;
        continue;
      }
      row.pack_bytes = *bytes;
      row.walk = *walked;
      if (!row.walk.gate.passed()) {
        std::printf("  %4d FAILED (first walk frame differs from brute force on %llu of %llu pixels)\n", k,
                    static_cast<unsigned long long>(row.walk.gate.mismatched),
                    static_cast<unsigned long long>(row.walk.gate.checked));
        exit_code = 1;
      } else {
        std::printf("  %4d %8u %8.0f %11zu %7.2f %8.2f %7.1f %7.2f %8.2f %7.2f %6.1f %6.2f\n", k, row.cluster_count,
                    row.bake_ms, row.pack_bytes, row.fuzzy_area_ratio, row.cluster_area_ratio, row.fps(),
                    row.walk.tests_per_ray, row.walk.work_per_ray, row.walk.skinning_ms, row.walk.cluster_bones,
                    row.walk.cluster_misses);
      }
      std::fflush(stdout);
      rep.clusters.push_back(row);
    }
  }

  rep.wall_s = ms_since(run_start) / 1000.0;
  std::printf("\n  columns: used = poses the bake really sampled; area = fuzzy / rest box area; tri/lf = triangles per\n"
              "  leaf; fps = walk, fallback on, shadows on; tst/ry = triangle tests per traced ray on that walk;\n"
              "  escaped = mean fraction of triangles routed to the\n"
              "  fallback on held-out poses; holes = fraction of held-out pixels (fallback off) whose primary hit\n"
              "  differs from brute force; pixels = pixels compared; fb ms = mean fallback phase; fb +ms = frame\n"
              "  time with the fallback on minus off at the hole size. Wall time %.1f s.\n",
              rep.wall_s);
  std::fflush(stdout);

  if (!write_output("tradeoff", "--json", o.json_path, report_json(rep).dump(2) + "\n")) return 1;
  if (!write_output("tradeoff", "--markdown", o.markdown_path, markdown(rep))) return 1;
  return exit_code;
}

}  // namespace sinew::bench
