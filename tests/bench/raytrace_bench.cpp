#include "tests/bench/bench_record.h"
#include "tests/bench/brute_force_gate.h"
#include "tests/bench/raytrace_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "character/bake.h"
#include "character/framing.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/cal3d_importer.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/jobs/job_system.h"
#include "runtime/memory/line_aligned.h"
#include "runtime/timing/phase_timers.h"
#include "tests/bench/bench_options.h"

namespace sinew::bench {
namespace {


constexpr double kFramesPerSecond = 30.0;
constexpr int kMaxImageSide = 16384;
constexpr int kGateStride = 7;

// --- options -----------------------------------------------------------------

struct BenchOptions {
  int width = 1024;
  int height = 1024;
  int frames = 30;
  std::vector<int> threads{1, 2};
  std::vector<std::string> models{"cally", "mannequin"};
  std::vector<int> instances{1, 4};
  std::string shared = SINEW_SHARED_DIR;
  rt::TriangleTest triangle_test = rt::TriangleTest::kFast;
  rt::BoneBoxMode bone_boxes = rt::BoneBoxMode::kExact;
  std::string json_path;  // empty: no JSON
  bool help = false;
};

std::vector<BenchFlag> bench_flags() {
  return {
      size_flag("1024x1024"),
      frames_flag("frames at 30 fps through the walk clip (default 30)"),
      thread_list_flag("1,2"),
      models_flag("cally and/or mannequin (default cally,mannequin)"),
      {"--instances", "LIST", "instance counts (default 1,4)"},
      shared_flag(),
      {"--triangle-test", "fast|watertight", "ray-triangle test (default fast)"},
      {"--bone-boxes", "exact|cheap", "per-frame bone boxes (default exact)"},
      json_flag(),
  };
}

const char* const kDescription = "ray tracer frame phases, and fuzzy vs exact kd-tree trace time\n";

Status read_options(const BenchArgs& parsed, BenchOptions& o) {
  namespace cli = sinew::cli;
  SINEW_RETURN_IF_ERROR(parsed.read_size(kMaxImageSide, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read("--frames", 1, 100000, o.frames));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--instances", 1, 256, o.instances));
  SINEW_RETURN_IF_ERROR(parsed.read_models(o.models));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  if (const auto text = parsed.value("--triangle-test")) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--triangle-test", *text, {"fast", "watertight"}));
    o.triangle_test = i == 0 ? rt::TriangleTest::kFast : rt::TriangleTest::kWatertight;
  }
  if (const auto text = parsed.value("--bone-boxes")) {
    SINEW_ASSIGN_OR_RETURN(const int i, cli::parse_choice("--bone-boxes", *text, {"exact", "cheap"}));
    o.bone_boxes = i == 0 ? rt::BoneBoxMode::kExact : rt::BoneBoxMode::kCheap;
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

// --- machine -------------------------------------------------------------------

// --- models --------------------------------------------------------------------

struct BenchModel {
  std::string name;
  character::Model model;
  std::size_t walk_clip = 0;
  character::InMemoryBake bake;
  int bake_threads = 0;
};

// --- one configuration ---------------------------------------------------------

// The exact SAH kd-tree side, measured on a few frames only (its build is
// the expensive part, and the point is the trace-time ratio, not its fps).
struct ExactComparison {
  std::vector<int> frames;
  // "build", "trace primary", "trace shadow" of the exact tree, and the
  // fuzzy scene's "fuzzy trace" on the same frames, one sample per frame.
  PhaseTimers timers;
  std::vector<double> ratios;  // per frame: fuzzy trace / exact trace (primary + shadow)
  bool hits_match = true;      // both structures hit the same number of pixels every frame
};

struct RunResult {
  int instances = 0;
  int threads = 0;
  // One sample per frame of every phase the scene and renderer record, plus
  // "top level + fallback" and "total".
  PhaseTimers timers;
  std::vector<double> mrays_per_s;  // per frame: (primary + shadow rays) / trace time
  std::uint64_t primary_rays = 0;   // last frame
  std::uint64_t shadow_rays = 0;
  std::size_t max_escaped_triangles = 0;
  ExactComparison exact;
  GateResult gate;  // the first frame's primary hits against brute force
};

double phase_median(const PhaseTimers& timers, std::string_view phase) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == phase) return s.median_ms;
  }
  return 0.0;
}

std::vector<int> comparison_frames(int frames) {
  std::vector<int> picked{0, (frames - 1) / 2, frames - 1};
  picked.erase(std::unique(picked.begin(), picked.end()), picked.end());
  return picked;
}

// Builds a scene whose only character geometry is one static mesh of the
// fuzzy scene's skinned world triangles, so the same rays meet the same
// triangles through an SAH tree built for exactly this pose.
Status compare_with_exact(const rt::Scene& fuzzy_scene, const SkinnedMesh& mesh, const rt::StaticMeshDesc& ground,
                          const rt::PinholeCamera& camera, const rt::RenderSettings& settings,
                          const rt::FrameBuffers& buffers, const rt::RenderStats& fuzzy, JobSystem& jobs,
                          rt::Renderer& renderer, ExactComparison& out) {
  rt::Scene exact;
  SINEW_ASSIGN_OR_RETURN(const double build_ms, build_exact_scene(fuzzy_scene, mesh, ground, jobs, exact));
  SINEW_ASSIGN_OR_RETURN(const rt::RenderStats traced, renderer.render(exact, camera, settings, buffers, jobs));

  const double fuzzy_trace = fuzzy.trace_primary_ms + fuzzy.trace_shadow_ms;
  const double exact_trace = traced.trace_primary_ms + traced.trace_shadow_ms;
  out.timers.record("build", build_ms);
  out.timers.record("trace primary", traced.trace_primary_ms);
  out.timers.record("trace shadow", traced.trace_shadow_ms);
  out.timers.record("exact trace", exact_trace);
  out.timers.record("fuzzy trace", fuzzy_trace);
  if (exact_trace > 0.0) out.ratios.push_back(fuzzy_trace / exact_trace);
  out.hits_match = out.hits_match && traced.primary_hits == fuzzy.primary_hits;
  return {};
}

Expected<RunResult> run_configuration(const BenchModel& m, const BenchOptions& o, int instances, int threads) {
  JobSystem jobs(threads);
  const character::Model& model = m.model;
  const anim::Clip& walk = model.clips[m.walk_clip];
  const Aabb rest = character::rest_bounds(model);
  const int up = character::up_axis_of(rest);

  rt::Scene scene;
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, scene.add_character(model.mesh, m.bake.fuzzy.view()));
  std::vector<std::uint32_t> ids;
  std::vector<Affine3> placements;
  for (int i = 0; i < instances; ++i) {
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t id, scene.add_instance(character));
    ids.push_back(id);
    placements.push_back(character::instance_placement(rest, i));
  }
  const rt::StaticMeshDesc ground = character::ground_plane_for(rest, instances);
  SINEW_RETURN_IF_ERROR(status_of(scene.add_static_mesh(ground)));

  rt::FrameOptions frame_options;
  frame_options.bone_boxes = o.bone_boxes;
  rt::RenderSettings settings;
  settings.triangle_test = o.triangle_test;
  settings.shadows = true;
  settings.light.kind = rt::Light::Kind::kPoint;

  // Colour only: shading runs and writes it, and no other AOV adds work the
  // table does not measure.
  LineAlignedVector<std::uint8_t> color(4 * static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height));
  rt::FrameBuffers buffers;
  buffers.width = o.width;
  buffers.height = o.height;
  buffers.color_rgba8 = color;

  RunResult run;
  run.instances = instances;
  run.threads = threads;
  run.exact.frames = comparison_frames(o.frames);
  rt::Renderer renderer;
  rt::Renderer exact_renderer;
  std::optional<rt::PinholeCamera> camera;
  for (int f = 0; f < o.frames; ++f) {
    const double seconds = f / kFramesPerSecond;
    PhaseTimers frame;
    {
      ScopedPhase animation(frame, "animation");
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const double t = seconds + character::instance_time_offset(static_cast<int>(i));
        SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> bones, character::clip_skinning(model, walk, t, placements[i]));
        SINEW_RETURN_IF_ERROR(scene.set_bones(ids[i], bones));
      }
    }
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats prepared, scene.prepare_frame(frame_options, jobs, &frame));
    if (!camera) {
      // Framed on the first frame's pose, as the render command does, so
      // every frame and every configuration of this size shares the view.
      const Aabb posed = character::posed_bounds(scene);
      settings.light.position = character::default_light(posed, up);
      SINEW_ASSIGN_OR_RETURN(camera,
                             rt::PinholeCamera::create(character::default_camera(posed, up, o.width, o.height), o.width, o.height));
    }
    SINEW_ASSIGN_OR_RETURN(const rt::RenderStats rendered,
                           renderer.render(scene, *camera, settings, buffers, jobs, &frame));

    // Every phase has exactly one sample in `frame`, so its median is it.
    double total = 0.0;
    for (const PhaseSummary& phase : frame.summarize()) {
      run.timers.record(phase.name, phase.median_ms);
      total += phase.median_ms;
    }
    run.timers.record("top level + fallback", phase_median(frame, "top level") + phase_median(frame, "fallback"));
    run.timers.record("total", total);
    const double trace_ms = rendered.trace_primary_ms + rendered.trace_shadow_ms;
    if (trace_ms > 0.0) {
      run.mrays_per_s.push_back(static_cast<double>(rendered.primary_rays + rendered.shadow_rays) / (trace_ms * 1e3));
    }
    run.primary_rays = rendered.primary_rays;
    run.shadow_rays = rendered.shadow_rays;
    run.max_escaped_triangles = std::max(run.max_escaped_triangles, prepared.escaped_triangles);

    if (f == 0) {
      // The benchmarks' rule (docs/BENCHMARKS.md): a configuration whose first frame disagrees with
      // brute force is not reported (every 7th pixel, untimed).
      const BruteForceGate gate(scene, *camera, kGateStride);
      SINEW_ASSIGN_OR_RETURN(const std::vector<Hit> hits, render_primary_hits(scene, *camera, settings, jobs));
      run.gate = gate.check(hits);
      if (!run.gate.passed()) return run;
    }
    if (std::find(run.exact.frames.begin(), run.exact.frames.end(), f) != run.exact.frames.end()) {
      SINEW_RETURN_IF_ERROR(compare_with_exact(scene, model.mesh, ground, *camera, settings, buffers, rendered, jobs,
                                               exact_renderer, run.exact));
    }
  }
  return run;
}

// --- report --------------------------------------------------------------------

double fps_of(const RunResult& run) {
  const double total = phase_median(run.timers, "total");
  return total > 0.0 ? 1000.0 / total : 0.0;
}

void print_model_header(const BenchModel& m) {
  const rt::FuzzyBakeStats& b = m.bake.fuzzy.stats;
  std::printf("\n%s: %zu triangles, %zu bones, %u pose samples (all clips, keys + 30 Hz)\n", m.name.c_str(),
              m.model.mesh.triangle_count(), m.model.skeleton.joint_count(), b.sample_count);
  std::printf("  bake (%d threads): pose sampling %.1f ms, sampling %.1f ms, assignment %.1f ms, build %.1f ms\n",
              m.bake_threads, m.bake.pose_sampling_ms, b.sampling_ms, b.assignment_ms, b.build_ms);
  std::printf("  fuzzy area %.4g (rest %.4g, ratio %.2f), %.2f triangles per leaf, max tree depth %d, %u nodes\n",
              b.fuzzy_area, b.rest_area, b.rest_area > 0.0 ? b.fuzzy_area / b.rest_area : 0.0,
              b.mean_items_per_leaf, b.max_depth, b.node_count);
}

void print_runs(const std::vector<RunResult>& runs) {
  std::printf("  frame phases, median ms:\n");
  std::printf("  %4s %3s %8s %8s %8s %8s %9s %9s %8s %9s %8s %7s\n", "inst", "thr", "anim", "skin", "boxes",
              "top+fb", "primary", "shadow", "shade", "total", "Mrays/s", "fps");
  for (const RunResult& r : runs) {
    std::printf("  %4d %3d %8.2f %8.2f %8.2f %8.2f %9.2f %9.2f %8.2f %9.2f %8.2f %7.2f\n", r.instances, r.threads,
                phase_median(r.timers, "animation"), phase_median(r.timers, "skinning"),
                phase_median(r.timers, "boxes"), phase_median(r.timers, "top level + fallback"),
                phase_median(r.timers, "trace primary"), phase_median(r.timers, "trace shadow"),
                phase_median(r.timers, "shade"), phase_median(r.timers, "total"), median_of(r.mrays_per_s),
                fps_of(r));
  }
  std::printf("  exact SAH kd-tree over the same skinned triangles, median ms:\n");
  std::printf("  %4s %3s %-9s %9s %9s %9s %11s %11s %11s %5s\n", "inst", "thr", "frames", "build", "primary",
              "shadow", "exact trace", "fuzzy trace", "fuzzy/exact", "hits");
  for (const RunResult& r : runs) {
    const ExactComparison& e = r.exact;
    std::printf("  %4d %3d %-9s %9.2f %9.2f %9.2f %11.2f %11.2f %11.2f %5s\n", r.instances, r.threads,
                join_ints(e.frames).c_str(), phase_median(e.timers, "build"), phase_median(e.timers, "trace primary"),
                phase_median(e.timers, "trace shadow"), phase_median(e.timers, "exact trace"),
                phase_median(e.timers, "fuzzy trace"), median_of(e.ratios), e.hits_match ? "same" : "DIFF");
  }
}

Json bake_json(const BenchModel& m) {
  const rt::FuzzyBakeStats& b = m.bake.fuzzy.stats;
  return {{"threads", m.bake_threads},       {"pose_sampling_ms", m.bake.pose_sampling_ms},
          {"sampling_ms", b.sampling_ms},    {"assignment_ms", b.assignment_ms},
          {"build_ms", b.build_ms},          {"fuzzy_area", b.fuzzy_area},
          {"rest_area", b.rest_area},        {"mean_triangles_per_leaf", b.mean_items_per_leaf},
          {"max_depth", b.max_depth},        {"node_count", b.node_count},
          {"samples", b.sample_count}};
}

Json run_json(const RunResult& r) {
  const ExactComparison& e = r.exact;
  Json phases = Json::parse(r.timers.json(), nullptr, false);
  Json exact_phases = Json::parse(e.timers.json(), nullptr, false);
  return {{"instances", r.instances},
          {"threads", r.threads},
          {"phases", phases},
          {"mrays_per_s", median_of(r.mrays_per_s)},
          {"fps", fps_of(r)},
          {"primary_rays", r.primary_rays},
          {"shadow_rays", r.shadow_rays},
          {"max_escaped_triangles", r.max_escaped_triangles},
          {"brute_force", {{"checked", r.gate.checked}, {"edge_grazes", r.gate.grazes}}},
          {"exact",
           {{"frames", e.frames},
            {"phases", exact_phases},
            {"fuzzy_over_exact", median_of(e.ratios)},
            {"primary_hits_match", e.hits_match}}}};
}

const char* triangle_test_name(rt::TriangleTest t) { return t == rt::TriangleTest::kFast ? "fast" : "watertight"; }
const char* bone_boxes_name(rt::BoneBoxMode b) { return b == rt::BoneBoxMode::kExact ? "exact" : "cheap"; }

}  // namespace

int run_raytrace_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("raytrace", kDescription, bench_flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const BenchOptions& o = *parsed;

  BenchRecord record("raytrace", command_line, o.threads);
  std::printf("  %dx%d, %d frames at 30 fps through the walk clip (instance i %.2f s later), point light,\n"
              "  shadows on, diffuse shading, triangle test %s, bone boxes %s, fallback on; each\n"
              "  configuration's first frame is checked against brute force (every 7th pixel)\n",
              o.width, o.height, o.frames, character::instance_time_offset(1), triangle_test_name(o.triangle_test),
              bone_boxes_name(o.bone_boxes));
  std::fflush(stdout);
  Json& doc = record.doc();
  doc["size"] = {o.width, o.height};
  doc["frames"] = o.frames;
  doc["triangle_test"] = triangle_test_name(o.triangle_test);
  doc["bone_boxes"] = bone_boxes_name(o.bone_boxes);
  doc["models"] = Json::array();

  // The bake is timed once per model, on the most threads the run uses.
  const int bake_threads = *std::max_element(o.threads.begin(), o.threads.end());
  for_each_model(record, o.models, o.shared, [&](const std::string& name, character::Model model) -> Status {
    BenchModel m;
    m.name = name;
    m.model = std::move(model);
    SINEW_ASSIGN_OR_RETURN(m.walk_clip, find_walk_clip(m.model, name));
    {
      JobSystem jobs(bake_threads);
      SINEW_ASSIGN_OR_RETURN(m.bake, character::bake_in_memory(m.model, character::BakeRequest{}, jobs));
      m.bake_threads = bake_threads;
    }
    print_model_header(m);
    std::fflush(stdout);

    std::vector<RunResult> runs;
    for (int instances : o.instances) {
      for (int threads : o.threads) {
        auto run = run_configuration(m, o, instances, threads);
        if (!run.ok()) {
          record.fail(name, run.status());
          continue;
        }
        if (!run->gate.passed()) {
          std::printf("  %d instances, %d threads: FAILED brute-force check (%llu of %llu sampled pixels differ): "
                      "not reported\n",
                      instances, threads, static_cast<unsigned long long>(run->gate.mismatched),
                      static_cast<unsigned long long>(run->gate.checked));
          record.mark_failed();
          continue;
        }
        runs.push_back(std::move(*run));
      }
    }
    print_runs(runs);
    std::fflush(stdout);

    Json model_doc = {{"name", name},
                      {"triangles", m.model.mesh.triangle_count()},
                      {"bones", m.model.skeleton.joint_count()},
                      {"bake", bake_json(m)},
                      {"runs", Json::array()}};
    for (const RunResult& r : runs) model_doc["runs"].push_back(run_json(r));
    doc["models"].push_back(std::move(model_doc));
    return {};
  });

  std::printf("\n  anim = clip_skinning + set_bones for all instances; top+fb = top-level build + fallback;\n"
              "  Mrays/s = (primary + shadow rays) / (primary + shadow trace time); fps = 1000 / median total.\n"
              "  The exact tree is rebuilt on the listed frames over the posed triangles (Wald-Havran SAH\n"
              "  sweep over triangle boxes, the static-mesh builder); fuzzy/exact is the median ratio of trace\n"
              "  times on those frames; hits = both found the same number of primary hits.\n");
  return record.finish(o.json_path);
}

}  // namespace sinew::bench
