#include "tests/bench/bake_bench.h"
#include "tests/bench/bench_record.h"

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include "character/bake.h"
#include "character/framing.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/cal3d_importer.h"
#include "raytrace/bake/fuzzy_bake.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_options.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;

// The machine is noisy: every time printed is a median of this many runs.
constexpr int kBakeRepeats = 3;
constexpr int kRenderRepeats = 5;
constexpr int kImageSide = 1024;
constexpr double kTraceFrameSeconds = 0.5;  // the walk clip's pose that is traced
constexpr double kMiB = 1024.0 * 1024.0;

template <typename T>
Status status_of(const Expected<T>& result) {
  return result.ok() ? Status{} : result.status();
}


double mib(std::size_t bytes) { return static_cast<double>(bytes) / kMiB; }

const char* mode_name(rt::CandidateBones mode) {
  return mode == rt::CandidateBones::kAll ? "all" : "influencing";
}

// --- options -------------------------------------------------------------------

struct BakeBenchOptions {
  std::vector<std::string> models{"cally", "mannequin"};
  std::string shared = SINEW_SHARED_DIR;
  int threads = JobSystem::hardware_threads();
  bool large = true;
  std::string json_path;  // empty: no JSON
  bool help = false;
};

std::vector<BenchFlag> bake_flags() {
  return {
      models_flag("cally and/or mannequin (default cally,mannequin)"),
      shared_flag(),
      threads_flag("0: all cores"),
      {"--large", "on|off",
       "the memory-bound bakes of a synthetic 300k-triangle x 60-bone\n"
       "character at 256, 64 and 16 MiB budgets (default on)"},
      json_flag(),
  };
}

const char* const kDescription = "fuzzy bake cost per candidate-bone mode, its trace effect, and its memory bound\n";

Status read_options(const BenchArgs& parsed, BakeBenchOptions& o) {
  SINEW_RETURN_IF_ERROR(parsed.read_models(o.models));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--large", o.large));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

// --- machine -------------------------------------------------------------------

// The process's resident high-water mark since it started (ru_maxrss, KiB on
// Linux). It never goes down, so it only shows a bake's footprint when that
// bake is the largest so far.
double max_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// Linux lets a process reset its own VmHWM (clear_refs "5"), which gives each
// bake its own peak; false where the kernel refuses.
bool reset_peak_rss() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

std::optional<double> status_kib(std::string_view key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) != 0) continue;
    return std::strtod(line.c_str() + key.size(), nullptr) / 1024.0;
  }
  return std::nullopt;
}

// --- real models ---------------------------------------------------------------


// One candidate mode on one model: the last of its bakes (kept for the
// renders), every bake's times, and every render's trace times.
struct ModeResult {
  rt::CandidateBones mode = rt::CandidateBones::kAll;
  character::InMemoryBake bake;
  PhaseTimers bake_timers;   // "pose sampling", "sampling", "assignment", "build", "total"
  PhaseTimers trace_timers;  // "primary", "shadow", "trace"
  std::uint64_t primary_hits = 0;
  std::size_t escaped_triangles = 0;
};

double phase_median(const PhaseTimers& timers, std::string_view phase) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == phase) return s.median_ms;
  }
  return 0.0;
}

Status bake_mode(const character::Model& model, JobSystem& jobs, ModeResult& out) {
  character::BakeRequest request;
  request.fuzzy.candidates = out.mode;
  for (int i = 0; i < kBakeRepeats; ++i) {
    const Clock::time_point start = Clock::now();
    SINEW_ASSIGN_OR_RETURN(character::InMemoryBake bake, character::bake_in_memory(model, request, jobs));
    const double total = ms_since(start);
    const rt::FuzzyBakeStats& s = bake.fuzzy.stats;
    out.bake_timers.record("pose sampling", bake.pose_sampling_ms);
    out.bake_timers.record("sampling", s.sampling_ms);
    out.bake_timers.record("assignment", s.assignment_ms);
    out.bake_timers.record("build", s.build_ms);
    out.bake_timers.record("total", total);
    out.bake = std::move(bake);
  }
  return {};
}

// Renders the walk clip's pose at kTraceFrameSeconds with the mode's bake,
// framed and lit as `sinew render` and the raytrace bench do.
Status trace_mode(const character::Model& model, const anim::Clip& walk, JobSystem& jobs, ModeResult& out) {
  const Aabb rest = character::rest_bounds(model);
  const int up = character::up_axis_of(rest);
  rt::Scene scene;
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene.add_character(model.mesh, out.bake.fuzzy.view()));
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t instance, scene.add_instance(character));
  SINEW_RETURN_IF_ERROR(status_of(scene.add_static_mesh(character::ground_plane_for(rest, 1))));
  SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> bones,
                         character::clip_skinning(model, walk, kTraceFrameSeconds, character::instance_placement(rest, 0)));
  SINEW_RETURN_IF_ERROR(scene.set_bones(instance, bones));
  SINEW_ASSIGN_OR_RETURN(const rt::FrameStats prepared, scene.prepare_frame(rt::FrameOptions{}, jobs));
  out.escaped_triangles = prepared.escaped_triangles;

  const Aabb posed = character::posed_bounds(scene);
  rt::RenderSettings settings;
  settings.shadows = true;
  settings.light.kind = rt::Light::Kind::kPoint;
  settings.light.position = character::default_light(posed, up);
  SINEW_ASSIGN_OR_RETURN(const rt::PinholeCamera camera,
                         rt::PinholeCamera::create(character::default_camera(posed, up, kImageSide, kImageSide),
                                                   kImageSide, kImageSide));
  std::vector<std::uint8_t> color(4 * static_cast<std::size_t>(kImageSide) * kImageSide);
  rt::FrameBuffers buffers;
  buffers.width = kImageSide;
  buffers.height = kImageSide;
  buffers.color_rgba8 = color;
  rt::Renderer renderer;
  for (int i = 0; i < kRenderRepeats; ++i) {
    SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats, renderer.render(scene, camera, settings, buffers, jobs));
    out.trace_timers.record("primary", stats.trace_primary_ms);
    out.trace_timers.record("shadow", stats.trace_shadow_ms);
    out.trace_timers.record("trace", stats.trace_primary_ms + stats.trace_shadow_ms);
    out.primary_hits = stats.primary_hits;
  }
  return {};
}

struct ModelResult {
  std::string name;
  std::size_t triangles = 0;
  std::size_t bones = 0;
  std::vector<ModeResult> modes;
};

Expected<ModelResult> run_model(const std::string& name, character::Model model, JobSystem& jobs) {
  SINEW_ASSIGN_OR_RETURN(const std::size_t walk, find_walk_clip(model, name));
  ModelResult result;
  result.name = name;
  result.triangles = model.mesh.triangle_count();
  result.bones = model.skeleton.joint_count();
  for (rt::CandidateBones mode : {rt::CandidateBones::kAll, rt::CandidateBones::kInfluencing}) {
    ModeResult r;
    r.mode = mode;
    SINEW_RETURN_IF_ERROR(bake_mode(model, jobs, r));
    SINEW_RETURN_IF_ERROR(trace_mode(model, model.clips[walk], jobs, r));
    result.modes.push_back(std::move(r));
  }
  return result;
}

// Triangles whose bone differs from the first (all-bones) mode's bake: 0
// means both modes built the same trees, so any trace difference is noise.
std::size_t reassigned_triangles(const ModelResult& m, const ModeResult& r) {
  const std::vector<std::uint16_t>& reference = m.modes.front().bake.fuzzy.triangle_bone;
  const std::vector<std::uint16_t>& bones = r.bake.fuzzy.triangle_bone;
  std::size_t differ = 0;
  for (std::size_t t = 0; t < std::min(reference.size(), bones.size()); ++t) differ += reference[t] != bones[t];
  return differ;
}

double area_ratio(const rt::FuzzyBakeStats& s) { return s.rest_area > 0.0 ? s.fuzzy_area / s.rest_area : 0.0; }

// influencing / all of a median trace time (0 when either is missing).
double influencing_over_all(const ModelResult& m) {
  if (m.modes.size() != 2) return 0.0;
  const double all = phase_median(m.modes[0].trace_timers, "trace");
  return all > 0.0 ? phase_median(m.modes[1].trace_timers, "trace") / all : 0.0;
}

void print_model(const ModelResult& m) {
  const std::uint32_t samples = m.modes.empty() ? 0 : m.modes.front().bake.fuzzy.stats.sample_count;
  std::printf("\n%s: %zu triangles, %zu bones, %u pose samples (all clips, keys + 30 Hz)\n", m.name.c_str(),
              m.triangles, m.bones, samples);
  std::printf("  bake, median of %d, ms:\n", kBakeRepeats);
  std::printf("  %-11s %7s %7s %9s %9s %8s %9s %12s %6s %6s %5s %7s %8s\n", "candidates", "samples", "poses",
              "sampling", "assign", "build", "total", "fuzzy area", "/rest", "tri/lf", "depth", "nodes", "peak MiB");
  for (const ModeResult& r : m.modes) {
    const rt::FuzzyBakeStats& s = r.bake.fuzzy.stats;
    std::printf("  %-11s %7u %7.1f %9.1f %9.1f %8.1f %9.1f %12.7g %6.3f %6.2f %5d %7u %8.2f\n", mode_name(r.mode),
                s.sample_count, phase_median(r.bake_timers, "pose sampling"), phase_median(r.bake_timers, "sampling"),
                phase_median(r.bake_timers, "assignment"), phase_median(r.bake_timers, "build"),
                phase_median(r.bake_timers, "total"), s.fuzzy_area, area_ratio(s), s.mean_items_per_leaf,
                s.max_depth, s.node_count, mib(s.peak_bytes));
  }
  std::printf("  trace, walk at %.1f s, %dx%d, point light, shadows on, median of %d renders, ms:\n",
              kTraceFrameSeconds, kImageSide, kImageSide, kRenderRepeats);
  std::printf("  %-11s %9s %9s %9s %12s %8s %10s\n", "candidates", "primary", "shadow", "trace", "primary hits",
              "escaped", "reassigned");
  for (const ModeResult& r : m.modes) {
    std::printf("  %-11s %9.2f %9.2f %9.2f %12llu %8zu %10zu\n", mode_name(r.mode),
                phase_median(r.trace_timers, "primary"), phase_median(r.trace_timers, "shadow"),
                phase_median(r.trace_timers, "trace"), static_cast<unsigned long long>(r.primary_hits),
                r.escaped_triangles, reassigned_triangles(m, r));
  }
  std::printf("  trace influencing / all: %.3f\n", influencing_over_all(m));
}

Json model_json(const ModelResult& m) {
  Json modes = Json::array();
  for (const ModeResult& r : m.modes) {
    const rt::FuzzyBakeStats& s = r.bake.fuzzy.stats;
    modes.push_back({{"candidates", mode_name(r.mode)},
                     {"samples", s.sample_count},
                     {"bake_phases", Json::parse(r.bake_timers.json(), nullptr, false)},
                     {"fuzzy_area", s.fuzzy_area},
                     {"rest_area", s.rest_area},
                     {"fuzzy_over_rest", area_ratio(s)},
                     {"mean_triangles_per_leaf", s.mean_items_per_leaf},
                     {"max_depth", s.max_depth},
                     {"node_count", s.node_count},
                     {"peak_mib", mib(s.peak_bytes)},
                     {"trace_phases", Json::parse(r.trace_timers.json(), nullptr, false)},
                     {"primary_hits", r.primary_hits},
                     {"escaped_triangles", r.escaped_triangles},
                     {"reassigned_vs_all", reassigned_triangles(m, r)}});
  }
  return {{"name", m.name},
          {"triangles", m.triangles},
          {"bones", m.bones},
          {"modes", modes},
          {"trace_influencing_over_all", influencing_over_all(m)}};
}

// --- synthetic large character ---------------------------------------------------

// A tube along +x of kRings rings x kRingVertices vertices over a chain of
// kChainBones bones of unit length: 150,250 vertices, 300,000 triangles.
constexpr int kRings = 601;
constexpr int kRingVertices = 250;
constexpr int kChainBones = 60;
constexpr int kLargeSamples = 62;
constexpr float kBoneLength = 1.0f;
constexpr float kTubeRadius = 0.25f;
constexpr float kMaxJointAngle = 0.4f;  // radians, per joint and sample
constexpr std::uint32_t kPoseSeed = 20240611u;
// A bake slower than this on its own makes the next (smaller budget, more
// chunks) bake use fewer samples, so the run stays within minutes.
constexpr double kSlowBakeMs = 60000.0;

struct SyntheticCharacter {
  SkinnedMesh mesh;
  std::vector<int> parents;
  std::vector<Affine3> poses;  // kLargeSamples x kChainBones skinning matrices
};

float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

// Uniform on the unit sphere by rejection from the cube.
Vec3 random_axis(std::mt19937& rng) {
  for (;;) {
    const Vec3 v(2.0f * unit_float(rng) - 1.0f, 2.0f * unit_float(rng) - 1.0f, 2.0f * unit_float(rng) - 1.0f);
    const float length2 = glm::dot(v, v);
    if (length2 > 1e-4f && length2 <= 1.0f) return v / std::sqrt(length2);
  }
}

// Each vertex is weighted to the two bones whose midpoints are nearest,
// falling off linearly between the midpoints (one bone alone at the ends).
void weight_vertex(float x, std::array<std::uint16_t, kMaxInfluences>& joints,
                   std::array<float, kMaxInfluences>& weights) {
  const float t = x / kBoneLength - 0.5f;
  const int lower = std::clamp(static_cast<int>(std::floor(t)), 0, kChainBones - 2);
  const float upper_weight = std::clamp(t - static_cast<float>(lower), 0.0f, 1.0f);
  joints.fill(0);
  weights.fill(0.0f);
  joints[0] = static_cast<std::uint16_t>(lower);
  joints[1] = static_cast<std::uint16_t>(lower + 1);
  weights[0] = 1.0f - upper_weight;
  weights[1] = upper_weight;
}

SkinnedMesh make_tube() {
  SkinnedMesh mesh;
  const std::size_t vertices = static_cast<std::size_t>(kRings) * kRingVertices;
  mesh.positions.reserve(vertices);
  mesh.normals.reserve(vertices);
  mesh.joints.resize(vertices);
  mesh.weights.resize(vertices);
  const float length = kBoneLength * static_cast<float>(kChainBones);
  const float two_pi = 6.2831853f;
  for (int r = 0; r < kRings; ++r) {
    const float x = length * static_cast<float>(r) / static_cast<float>(kRings - 1);
    for (int k = 0; k < kRingVertices; ++k) {
      const float angle = two_pi * static_cast<float>(k) / static_cast<float>(kRingVertices);
      const Vec3 radial(0.0f, std::cos(angle), std::sin(angle));
      const std::size_t v = mesh.positions.size();
      mesh.positions.push_back(Vec3(x, 0.0f, 0.0f) + kTubeRadius * radial);
      mesh.normals.push_back(radial);
      weight_vertex(x, mesh.joints[v], mesh.weights[v]);
    }
  }
  const auto id = [](int ring, int k) {
    return static_cast<std::uint32_t>(ring * kRingVertices + (k % kRingVertices));
  };
  mesh.triangles.reserve(2 * static_cast<std::size_t>(kRings - 1) * kRingVertices);
  for (int r = 0; r + 1 < kRings; ++r) {
    for (int k = 0; k < kRingVertices; ++k) {
      mesh.triangles.push_back({id(r, k), id(r, k + 1), id(r + 1, k + 1)});
      mesh.triangles.push_back({id(r, k), id(r + 1, k + 1), id(r + 1, k)});
    }
  }
  return mesh;
}

// Skinning matrices (posed world * inverse bind world) of `samples` random
// poses of the chain; bone b's bind frame sits at x = b * kBoneLength.
std::vector<Affine3> make_chain_poses(int samples) {
  std::mt19937 rng(kPoseSeed);
  std::vector<Affine3> inverse_bind(kChainBones);
  for (int b = 0; b < kChainBones; ++b) {
    inverse_bind[static_cast<std::size_t>(b)] =
        inverse(Affine3::translation(Vec3(kBoneLength * static_cast<float>(b), 0.0f, 0.0f)));
  }
  std::vector<Affine3> poses;
  poses.reserve(static_cast<std::size_t>(samples) * kChainBones);
  std::vector<Affine3> world(kChainBones);
  for (int s = 0; s < samples; ++s) {
    for (int b = 0; b < kChainBones; ++b) {
      const Vec3 axis = random_axis(rng);
      const float angle = kMaxJointAngle * unit_float(rng);
      const Vec3 offset = b == 0 ? Vec3(0.0f) : Vec3(kBoneLength, 0.0f, 0.0f);
      const Affine3 local = Affine3::from_trs(offset, glm::angleAxis(angle, axis), Vec3(1.0f));
      const auto i = static_cast<std::size_t>(b);
      world[i] = b == 0 ? local : world[i - 1] * local;
      poses.push_back(world[i] * inverse_bind[i]);
    }
  }
  return poses;
}

SyntheticCharacter make_synthetic_character() {
  SyntheticCharacter c;
  c.mesh = make_tube();
  c.parents.resize(kChainBones);
  for (int b = 0; b < kChainBones; ++b) c.parents[static_cast<std::size_t>(b)] = b - 1;
  c.poses = make_chain_poses(kLargeSamples);
  return c;
}

struct LargeRun {
  std::size_t budget_bytes = 0;
  std::uint32_t samples = 0;
  rt::FuzzyBakeStats stats;
  double total_ms = 0.0;
  std::size_t output_bytes = 0;         // the baked arrays the bake returns
  double max_rss_mib = 0.0;             // getrusage's high-water mark after the bake
  std::optional<double> bake_hwm_mib;   // VmHWM since just before the bake
};

struct LargeResult {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double baseline_rss_mib = 0.0;  // after building the mesh and poses, before any bake
  std::vector<LargeRun> runs;
  std::vector<std::string> notes;
};

template <typename T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

std::size_t output_bytes(const rt::FuzzyCharacterData& d) {
  return bytes_of(d.triangle_bone) + bytes_of(d.bone_trees) + bytes_of(d.nodes) + bytes_of(d.items) +
         bytes_of(d.vertex_check_begin) + bytes_of(d.vertex_checks) + bytes_of(d.triangle_checks);
}

Expected<LargeRun> bake_large(const SyntheticCharacter& c, std::size_t budget, int samples, JobSystem& jobs) {
  rt::FuzzyBakeInput input;
  input.mesh = &c.mesh;
  input.bone_count = kChainBones;
  input.bone_parents = c.parents;
  input.samples = std::span<const Affine3>(c.poses).first(static_cast<std::size_t>(samples) * kChainBones);
  rt::FuzzyBakeOptions options;
  options.candidates = rt::CandidateBones::kAll;
  options.memory_budget_bytes = budget;
  LargeRun run;
  run.budget_bytes = budget;
  const bool reset = reset_peak_rss();
  const Clock::time_point start = Clock::now();
  {
    SINEW_ASSIGN_OR_RETURN(const rt::FuzzyCharacterData baked, rt::bake_fuzzy_character(input, options, jobs));
    run.total_ms = ms_since(start);
    run.stats = baked.stats;
    run.output_bytes = output_bytes(baked);
  }
  run.samples = run.stats.sample_count;
  run.max_rss_mib = max_rss_mib();
  if (reset) run.bake_hwm_mib = status_kib("VmHWM:");
  return run;
}

Expected<LargeResult> run_large(JobSystem& jobs) {
  const SyntheticCharacter c = make_synthetic_character();
  LargeResult result;
  result.vertices = c.mesh.vertex_count();
  result.triangles = c.mesh.triangle_count();
  result.baseline_rss_mib = status_kib("VmRSS:").value_or(0.0);
  int samples = kLargeSamples;
  const std::array<std::size_t, 3> budgets_mib{256, 64, 16};
  for (std::size_t i = 0; i < budgets_mib.size(); ++i) {
    const std::size_t budget_mib = budgets_mib[i];
    SINEW_ASSIGN_OR_RETURN(LargeRun run, bake_large(c, budget_mib << 20, samples, jobs));
    result.runs.push_back(run);
    std::printf("  (baked at %zu MiB in %.0f ms)\n", budget_mib, run.total_ms);
    std::fflush(stdout);
    const bool another = i + 1 < budgets_mib.size();
    if (another && run.total_ms > kSlowBakeMs && samples > 8) {
      // A smaller budget means more chunks, each re-skinning every sample.
      const int reduced = std::max(8, static_cast<int>(samples * kSlowBakeMs / (2.0 * run.total_ms)));
      result.notes.push_back("the " + std::to_string(budget_mib) + " MiB bake took " +
                             std::to_string(static_cast<int>(run.total_ms / 1000.0)) +
                             " s: the next budget bakes " + std::to_string(reduced) + " samples instead of " +
                             std::to_string(samples));
      samples = reduced;
    }
  }
  return result;
}

// Whether two bakes of the same input made the same trees (chunking must not
// change the result); only comparable at the same sample count.
bool same_bake(const rt::FuzzyBakeStats& a, const rt::FuzzyBakeStats& b) {
  return a.sample_count == b.sample_count && a.fuzzy_area == b.fuzzy_area && a.node_count == b.node_count &&
         a.max_depth == b.max_depth;
}

std::size_t unchunked_box_bytes(const LargeResult& r) {
  return r.vertices * kChainBones * sizeof(Aabb);
}

std::size_t all_positions_bytes(const LargeResult& r, std::uint32_t samples) {
  return static_cast<std::size_t>(samples) * r.vertices * 3 * sizeof(float);
}

void print_large(const LargeResult& r) {
  std::printf("\nsynthetic tube: %zu vertices, %zu triangles, %d bones in a chain, %d random poses "
              "(<= %.1f rad per joint), candidates all\n",
              r.vertices, r.triangles, kChainBones, kLargeSamples, static_cast<double>(kMaxJointAngle));
  std::printf("  unchunked would need: vertex boxes V x B x %zu B = %.1f MiB; all skinned positions S x V x 12 B "
              "= %.1f MiB\n",
              sizeof(Aabb), mib(unchunked_box_bytes(r)), mib(all_positions_bytes(r, kLargeSamples)));
  std::printf("  RSS before the bakes (mesh + poses + earlier work): %.1f MiB\n", r.baseline_rss_mib);
  std::printf("  %7s %7s %9s %9s %8s %9s %8s %8s %8s %8s %10s %6s %7s %s\n", "budget", "samples", "sampling",
              "assign", "build", "total", "peak MiB", "out MiB", "HWM MiB", "+RSS MiB", "maxrss MiB", "/rest",
              "nodes", "result");
  const LargeRun* first = r.runs.empty() ? nullptr : &r.runs.front();
  for (const LargeRun& run : r.runs) {
    char hwm[16] = "n/a";
    char added[16] = "n/a";
    if (run.bake_hwm_mib) {
      std::snprintf(hwm, sizeof hwm, "%.1f", *run.bake_hwm_mib);
      std::snprintf(added, sizeof added, "%.1f", *run.bake_hwm_mib - r.baseline_rss_mib);
    }
    const char* same = first == nullptr || first->samples != run.samples ? "-"
                       : same_bake(first->stats, run.stats)               ? "same"
                                                                          : "DIFF";
    std::printf("  %3zu MiB %7u %9.1f %9.1f %8.1f %9.1f %8.1f %8.1f %8s %8s %10.1f %6.2f %7u %s\n",
                run.budget_bytes >> 20, run.samples, run.stats.sampling_ms, run.stats.assignment_ms,
                run.stats.build_ms, run.total_ms, mib(run.stats.peak_bytes), mib(run.output_bytes), hwm, added,
                run.max_rss_mib, area_ratio(run.stats), run.stats.node_count, same);
  }
  for (const std::string& note : r.notes) std::printf("  note: %s\n", note.c_str());
  std::printf("  peak MiB = the bake's own largest working set (FuzzyBakeStats::peak_bytes; the budget bounds\n"
              "  only its box chunk, not the output); out MiB = the returned arrays; HWM = the process's\n"
              "  resident peak during that bake (VmHWM reset through /proc/self/clear_refs just before it);\n"
              "  +RSS = HWM - RSS before the bakes (approximate: freed heap is reused); maxrss = getrusage\n"
              "  ru_maxrss after the bake (on Linux it follows the reset too); result = same trees (area,\n"
              "  nodes, depth) as the first budget.\n");
}

Json large_json(const LargeResult& r) {
  Json runs = Json::array();
  for (const LargeRun& run : r.runs) {
    runs.push_back({{"budget_mib", run.budget_bytes >> 20},
                    {"samples", run.samples},
                    {"sampling_ms", run.stats.sampling_ms},
                    {"assignment_ms", run.stats.assignment_ms},
                    {"build_ms", run.stats.build_ms},
                    {"total_ms", run.total_ms},
                    {"peak_mib", mib(run.stats.peak_bytes)},
                    {"output_mib", mib(run.output_bytes)},
                    {"bake_hwm_mib", run.bake_hwm_mib ? Json(*run.bake_hwm_mib) : Json(nullptr)},
                    {"max_rss_mib", run.max_rss_mib},
                    {"fuzzy_over_rest", area_ratio(run.stats)},
                    {"node_count", run.stats.node_count},
                    {"max_depth", run.stats.max_depth}});
  }
  return {{"vertices", r.vertices},
          {"triangles", r.triangles},
          {"bones", kChainBones},
          {"samples", kLargeSamples},
          {"unchunked_box_mib", mib(unchunked_box_bytes(r))},
          {"all_positions_mib", mib(all_positions_bytes(r, kLargeSamples))},
          {"baseline_rss_mib", r.baseline_rss_mib},
          {"runs", runs},
          {"notes", r.notes}};
}

}  // namespace

int run_bake_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("bake", kDescription, bake_flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const BakeBenchOptions& o = *parsed;

  BenchRecord record("bake", command_line, o.threads);
  std::fflush(stdout);
  Json& doc = record.doc();
  doc["bake_repeats"] = kBakeRepeats;
  doc["render_repeats"] = kRenderRepeats;
  doc["models"] = Json::array();

  JobSystem jobs(o.threads);
  for_each_model(record, o.models, o.shared, [&](const std::string& name, character::Model model) -> Status {
    SINEW_ASSIGN_OR_RETURN(const auto result, run_model(name, std::move(model), jobs));
    print_model(result);
    std::fflush(stdout);
    doc["models"].push_back(model_json(result));
    return {};
  });
  if (!o.models.empty()) {
    std::printf("\n  poses = producing the samples' matrices; sampling/assign/build = FuzzyBakeStats phases;\n"
                "  total = the whole bake_in_memory call; /rest = fuzzy area / bind-pose area; tri/lf = mean\n"
                "  triangles per non-empty leaf; peak MiB = the bake's largest working set; trace = primary +\n"
                "  shadow; escaped = triangles routed through the fallback in the traced frame;\n"
                "  reassigned = triangles whose bone differs from the all-bones bake (0: same trees).\n");
  }

  if (o.large) {
    const auto large = run_large(jobs);
    if (!large.ok()) {
      record.fail("synthetic", large.status());
    } else {
      print_large(*large);
      doc["large"] = large_json(*large);
    }
  }

  return record.finish(o.json_path);
}

}  // namespace sinew::bench
