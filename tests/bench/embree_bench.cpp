#include "tests/bench/embree_bench.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "editor/bake/in_memory_bake.h"
#include "editor/cli/cli_args.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/brute_force_gate.h"
#ifdef SINEW_HAVE_EMBREE
#include "tests/bench/embree_tracer.h"
#endif

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

constexpr double kFramesPerSecond = 30.0;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// --- options -------------------------------------------------------------------

struct Options {
  int width = 1024;
  int height = 1024;
  int frames = 120;
  std::vector<int> threads{1, 2};
  std::vector<std::string> clips{"walk"};
  std::string model = "cally";
  int instances = 1;
  int subdivide = 0;  // subdivision levels applied to the model (Table 2's larger meshes)
  int check_stride = 7;
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  bool help = false;
};

const std::vector<editor::cli::FlagSpec>& flags() {
  static const std::vector<editor::cli::FlagSpec> specs = {
      {"--help", false}, {"-h", false},        {"--quick", false}, {"--size"},   {"--frames"}, {"--threads"},
      {"--clips"},       {"--clip"},           {"--model"},        {"--instances"}, {"--shared"}, {"--json"},
      {"--check-stride"}, {"--subdivide"},
  };
  return specs;
}

Expected<Options> parse_options(const std::vector<std::string>& args) {
  namespace cli = editor::cli;
  SINEW_ASSIGN_OR_RETURN(const cli::ParsedArgs parsed, parse_bench_args(args, flags()));
  Options o;
  if (wants_help(parsed)) {
    o.help = true;
    return o;
  }
  if (parsed.has("--quick")) {  // explicit flags below still override
    o.width = o.height = 256;
    o.frames = 30;
    o.threads = {1};
  }
  if (const auto text = parsed.value("--size")) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--size", *text, 16384));
    o.width = size.width;
    o.height = size.height;
  }
  if (const auto text = parsed.value("--frames")) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--frames", *text, 1, 100000));
    o.frames = static_cast<int>(n);
  }
  if (const auto text = parsed.value("--threads")) {
    SINEW_ASSIGN_OR_RETURN(o.threads, parse_int_list("--threads", *text, 1, 1024));
  }
  if (parsed.has("--clip") && parsed.has("--clips")) {
    return invalid_argument("--clip", *parsed.value("--clip"), "give --clip or --clips, not both");
  }
  if (const auto text = parsed.value("--clip")) o.clips = {*text};
  if (const auto text = parsed.value("--clips")) {
    SINEW_ASSIGN_OR_RETURN(o.clips, cli::parse_list("--clips", *text));
  }
  if (const auto text = parsed.value("--model")) o.model = *text;
  if (const auto text = parsed.value("--instances")) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--instances", *text, 1, 256));
    o.instances = static_cast<int>(n);
  }
  if (const auto text = parsed.value("--subdivide")) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n,
                           cli::parse_int("--subdivide", *text, 0, editor::kMaxSubdivisionLevels));
    o.subdivide = static_cast<int>(n);
  }
  if (const auto text = parsed.value("--check-stride")) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--check-stride", *text, 1, 1 << 20));
    o.check_stride = static_cast<int>(n);
  }
  if (const auto text = parsed.value("--shared")) o.shared = *text;
  if (const auto text = parsed.value("--json")) o.json_path = *text;
  return o;
}

void print_usage(std::FILE* to) {
  std::fprintf(to,
               "usage: sinew-bench embree [--quick] [--model NAME|PATH] [--instances N] [--frames N]\n"
               "                          [--clips LIST | --clip NAME] [--size WxH] [--threads LIST]\n"
               "                          [--subdivide LEVELS] [--check-stride N] [--shared DIR] [--json FILE]\n"
               "  --quick             256x256, 30 frames, 1 thread (later flags override)\n"
               "  --model M           cally (default), mannequin, or a .gltf/.glb/.cfg/.pack path\n"
               "  --instances N       character instances (default 1)\n"
               "  --frames N          frames at 30 fps through each clip (default 120)\n"
               "  --clips LIST        clips to animate, e.g. walk,tornado_kick (default walk)\n"
               "  --size WxH          image size (default 1024x1024)\n"
               "  --threads LIST      thread counts (default 1,2)\n"
               "  --subdivide L       subdivide the model L times first (each level: 4x the triangles)\n"
               "  --check-stride N    brute-force check every Nth pixel of the first frame (default 7)\n"
               "  --shared DIR        the shared folder holding content/cal3d/cally\n"
               "  --json FILE         also write the numbers as JSON\n");
}

// --- contenders ----------------------------------------------------------------

enum class Contender : std::uint8_t { kSinew, kEmbreeLow, kEmbreeRefit, kEmbreeMedium, kExact };

const char* contender_name(Contender c) {
  switch (c) {
    case Contender::kSinew: return "sinew fuzzy kd";
    case Contender::kEmbreeLow: return "embree LOW rebuild";
    case Contender::kEmbreeRefit: return "embree refit";
    case Contender::kEmbreeMedium: return "embree MEDIUM rebuild";
    case Contender::kExact: return "exact SAH kd rebuild";
  }
  return "?";
}

struct ContenderResult {
  Contender which = Contender::kSinew;
  PhaseTimers timers;  // "build", "trace primary", "trace shadow", "trace", "shade", "total"
  GateResult gate;
  std::uint64_t primary_hits = 0;  // last frame
  std::uint64_t shadow_rays = 0;   // last frame
};

struct ConfigResult {
  std::string clip;
  int threads = 0;
  PhaseTimers shared;  // "animation", "skinning"
  std::vector<ContenderResult> contenders;
};

// One frame's numbers of one contender.
struct FrameSample {
  double build_ms = 0.0;
  double primary_ms = 0.0;
  double shadow_ms = 0.0;
  double shade_ms = 0.0;
  std::uint64_t primary_hits = 0;
  std::uint64_t shadow_rays = 0;
};

void record(ContenderResult& r, const FrameSample& s, double skinning_ms) {
  r.timers.record("build", s.build_ms);
  r.timers.record("trace primary", s.primary_ms);
  r.timers.record("trace shadow", s.shadow_ms);
  r.timers.record("trace", s.primary_ms + s.shadow_ms);
  r.timers.record("shade", s.shade_ms);
  r.timers.record("total", skinning_ms + s.build_ms + s.primary_ms + s.shadow_ms + s.shade_ms);
  r.primary_hits = s.primary_hits;
  r.shadow_rays = s.shadow_rays;
}

double phase(const PhaseTimers& timers, std::string_view name) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == name) return s.median_ms;
  }
  return 0.0;
}

// The frame's fixed inputs shared by every contender.
struct FrameContext {
  const editor::ImportedModel* model = nullptr;
  BenchStage* stage = nullptr;
  rt::PinholeCamera camera;
  rt::RenderSettings settings;
  rt::FrameBuffers color;  // colour only
  JobSystem* jobs = nullptr;
};

FrameSample sinew_sample(const PhaseTimers& prepare, const rt::RenderStats& stats) {
  FrameSample s;
  s.build_ms = phase(prepare, "boxes") + phase(prepare, "fallback") + phase(prepare, "top level");
  s.primary_ms = stats.trace_primary_ms;
  s.shadow_ms = stats.trace_shadow_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  return s;
}

// The exact scene's merged-mesh ids back to the fuzzy scene's: triangle
// i*T + t of slot 0 is instance i's triangle t; slot 1 is the ground.
void map_exact_ids(const rt::Scene& fuzzy, std::size_t triangles_per_instance, std::vector<Hit>& hits) {
  for (Hit& h : hits) {
    if (!h.valid()) continue;
    if (h.instance_id == 0) {
      const std::size_t i = h.triangle_id / triangles_per_instance;
      h.instance_id = fuzzy.instances()[i].instance_id;
      h.triangle_id = static_cast<std::uint32_t>(h.triangle_id % triangles_per_instance);
    } else {
      h.instance_id = fuzzy.static_meshes()[0].instance_id;
    }
  }
}

Expected<FrameSample> run_exact(const FrameContext& c, rt::Renderer& renderer, const BruteForceGate* gate,
                                GateResult* gate_out) {
  FrameSample s;
  rt::Scene exact;
  const Clock::time_point start = Clock::now();
  SINEW_RETURN_IF_ERROR(status_of(build_exact_scene(c.stage->scene, c.model->mesh, c.stage->ground, *c.jobs, exact)));
  s.build_ms = ms_since(start);  // the merge copy, the SAH build and the top level
  SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats, renderer.render(exact, c.camera, c.settings, c.color, *c.jobs));
  s.primary_ms = stats.trace_primary_ms;
  s.shadow_ms = stats.trace_shadow_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  if (gate) {
    SINEW_ASSIGN_OR_RETURN(std::vector<Hit> hits, render_primary_hits(exact, c.camera, c.settings, *c.jobs));
    map_exact_ids(c.stage->scene, c.model->mesh.triangles.size(), hits);
    *gate_out = gate->check(hits);
  }
  return s;
}

#ifdef SINEW_HAVE_EMBREE
Expected<FrameSample> run_embree(const FrameContext& c, EmbreeTracer& tracer, std::span<std::uint8_t> color,
                                 const BruteForceGate* gate, GateResult* gate_out) {
  FrameSample s;
  SINEW_ASSIGN_OR_RETURN(s.build_ms, tracer.update(c.stage->scene));
  SINEW_ASSIGN_OR_RETURN(const EmbreeRenderStats stats,
                         tracer.render(c.stage->scene, c.camera, c.settings, color, {}, *c.jobs));
  s.primary_ms = stats.trace_primary_ms;
  s.shadow_ms = stats.trace_shadow_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  if (gate) {
    std::vector<Hit> hits(static_cast<std::size_t>(c.camera.width()) * static_cast<std::size_t>(c.camera.height()));
    SINEW_RETURN_IF_ERROR(status_of(tracer.render(c.stage->scene, c.camera, c.settings, {}, hits, *c.jobs)));
    *gate_out = gate->check(hits);
  }
  return s;
}

EmbreeMode mode_of(Contender c) {
  return c == Contender::kEmbreeLow     ? EmbreeMode::kRebuildLow
         : c == Contender::kEmbreeRefit ? EmbreeMode::kRefit
                                        : EmbreeMode::kRebuildMedium;
}
#endif

std::vector<Contender> contenders() {
#ifdef SINEW_HAVE_EMBREE
  return {Contender::kSinew, Contender::kEmbreeLow, Contender::kEmbreeRefit, Contender::kEmbreeMedium,
          Contender::kExact};
#else
  return {Contender::kSinew, Contender::kExact};
#endif
}

Expected<ConfigResult> run_configuration(const editor::ImportedModel& model, const rt::FuzzyCharacterView& fuzzy,
                                         const Options& o, const std::string& clip_name, std::size_t clip,
                                         int threads) {
  JobSystem jobs(threads);
  BenchStage stage;
  SINEW_RETURN_IF_ERROR(stage_instances(model, fuzzy, o.instances, stage));

  ConfigResult result;
  result.clip = clip_name;
  result.threads = threads;
  const std::vector<Contender> order = contenders();
  for (Contender c : order) result.contenders.push_back(ContenderResult{c, {}, {}, 0, 0});

#ifdef SINEW_HAVE_EMBREE
  std::array<std::unique_ptr<EmbreeTracer>, 5> tracers;
  for (Contender c : {Contender::kEmbreeLow, Contender::kEmbreeRefit, Contender::kEmbreeMedium}) {
    SINEW_ASSIGN_OR_RETURN(tracers[static_cast<std::size_t>(c)], EmbreeTracer::create(mode_of(c), threads));
  }
#endif

  std::vector<std::uint8_t> color(4 * static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height));
  FrameContext ctx;
  ctx.model = &model;
  ctx.stage = &stage;
  ctx.jobs = &jobs;
  ctx.settings.shadows = true;
  ctx.settings.light.kind = rt::Light::Kind::kPoint;
  ctx.color.width = o.width;
  ctx.color.height = o.height;
  ctx.color.color_rgba8 = color;
  rt::Renderer sinew_renderer;
  rt::Renderer exact_renderer;
  std::optional<BruteForceGate> gate;

  for (int f = 0; f < o.frames; ++f) {
    const Clock::time_point animation_start = Clock::now();
    SINEW_RETURN_IF_ERROR(pose_instances(model, model.clips[clip], f / kFramesPerSecond, stage));
    result.shared.record("animation", ms_since(animation_start));
    // Sinew's skinning is every contender's skinning; its boxes, fallback
    // and top level are Sinew's per-frame build.
    PhaseTimers prepare;
    SINEW_RETURN_IF_ERROR(status_of(stage.scene.prepare_frame(rt::FrameOptions{}, jobs, &prepare)));
    const double skinning_ms = phase(prepare, "skinning");
    result.shared.record("skinning", skinning_ms);
    if (f == 0) {
      const Aabb posed = editor::posed_bounds(stage.scene);
      ctx.settings.light.position = editor::default_light(posed, stage.up);
      SINEW_ASSIGN_OR_RETURN(ctx.camera, rt::PinholeCamera::create(editor::default_camera(posed, stage.up, o.width,
                                                                                          o.height),
                                                                   o.width, o.height));
      gate.emplace(stage.scene, ctx.camera, o.check_stride);
    }
    const BruteForceGate* check = f == 0 ? &*gate : nullptr;

    // Rotating the order frame by frame spreads the machine's noise (and
    // any cache warmth left by the previous contender) over all of them.
    for (std::size_t k = 0; k < order.size(); ++k) {
      ContenderResult& r = result.contenders[(k + static_cast<std::size_t>(f)) % order.size()];
      FrameSample sample;
      switch (r.which) {
        case Contender::kSinew: {
          SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats,
                                 sinew_renderer.render(stage.scene, ctx.camera, ctx.settings, ctx.color, jobs));
          sample = sinew_sample(prepare, stats);
          if (check) {
            SINEW_ASSIGN_OR_RETURN(const std::vector<Hit> hits, render_primary_hits(stage.scene, ctx.camera, ctx.settings, *ctx.jobs));
            r.gate = check->check(hits);
          }
          break;
        }
        case Contender::kExact: {
          SINEW_ASSIGN_OR_RETURN(sample, run_exact(ctx, exact_renderer, check, &r.gate));
          break;
        }
        default: {
#ifdef SINEW_HAVE_EMBREE
          SINEW_ASSIGN_OR_RETURN(sample, run_embree(ctx, *tracers[static_cast<std::size_t>(r.which)], color, check,
                                                    &r.gate));
#endif
          break;
        }
      }
      record(r, sample, skinning_ms);
    }
  }
  return result;
}

// --- report --------------------------------------------------------------------

std::string ratio_text(double sinew, double other) {
  if (!(other > 0.0)) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", sinew / other);
  return text;
}

void print_config(const ConfigResult& r) {
  std::printf("\n### clip %s, %d thread%s\n\n", r.clip.c_str(), r.threads, r.threads == 1 ? "" : "s");
  std::printf("shared per frame (median ms): animation %.3f, skinning %.3f (Sinew's, identical for all)\n\n",
              phase(r.shared, "animation"), phase(r.shared, "skinning"));
  std::printf("| contender | build/refit ms | primary ms | shadow ms | trace ms | shade ms | total ms | "
              "sinew/this build | sinew/this trace | sinew/this total | brute force |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  const ContenderResult& sinew = r.contenders.front();
  for (const ContenderResult& c : r.contenders) {
    const std::string check = std::to_string(c.gate.checked) + " px ok" +
                              (c.gate.grazes ? ", " + std::to_string(c.gate.grazes) + " edge grazes" : "");
    if (!c.gate.passed()) {
      std::printf("| %s | FAILED brute-force check (%llu of %llu sampled pixels differ) | | | | | | | | | FAILED |\n",
                  contender_name(c.which), static_cast<unsigned long long>(c.gate.mismatched),
                  static_cast<unsigned long long>(c.gate.checked));
      continue;
    }
    const double b = phase(c.timers, "build"), t = phase(c.timers, "trace"), tot = phase(c.timers, "total");
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %s | %s | %s |\n", contender_name(c.which), b,
                phase(c.timers, "trace primary"), phase(c.timers, "trace shadow"), t, phase(c.timers, "shade"), tot,
                ratio_text(phase(sinew.timers, "build"), b).c_str(), ratio_text(phase(sinew.timers, "trace"), t).c_str(),
                ratio_text(phase(sinew.timers, "total"), tot).c_str(), check.c_str());
  }
}

Json config_json(const ConfigResult& r) {
  Json doc = {{"clip", r.clip},
              {"threads", r.threads},
              {"shared", Json::parse(r.shared.json(), nullptr, false)},
              {"contenders", Json::array()}};
  for (const ContenderResult& c : r.contenders) {
    Json entry = {{"name", contender_name(c.which)},
                  {"brute_force",
                   {{"passed", c.gate.passed()},
                    {"checked", c.gate.checked},
                    {"mismatched", c.gate.mismatched},
                    {"edge_grazes", c.gate.grazes}}}};
    if (c.gate.passed()) {
      entry["phases"] = Json::parse(c.timers.json(), nullptr, false);
      entry["primary_hits"] = c.primary_hits;
      entry["shadow_rays"] = c.shadow_rays;
    }
    doc["contenders"].push_back(std::move(entry));
  }
  return doc;
}

}  // namespace

int run_embree_bench(const std::vector<std::string>& args, const std::string& command_line) {
  const auto parsed = parse_options(args);
  if (const std::optional<int> done = usage_exit("embree", parsed, print_usage)) return *done;
  const Options& o = *parsed;
  const std::string cpu = cpu_model();
  const std::string date = utc_date();
  print_bench_header("embree", command_line, join_ints(o.threads), cpu, date);
#ifdef SINEW_HAVE_EMBREE
  const bool have_embree = true;
#else
  const bool have_embree = false;
  std::printf("  Embree not found: its columns are skipped\n");
#endif
  std::printf("  model %s, %d instance%s, %dx%d, %d frames at 30 fps per clip, point light, shadows on,\n"
              "  diffuse shading; brute-force check of every %dth pixel of the first frame\n",
              o.model.c_str(), o.instances, o.instances == 1 ? "" : "s", o.width, o.height, o.frames,
              o.check_stride);
  std::fflush(stdout);

  Json doc = {{"command", command_line}, {"cpu", cpu}, {"commit", git_commit()}, {"load_average_start", load_average()},           {"hardware_threads", JobSystem::hardware_threads()},
              {"date", date},            {"model", o.model},     {"subdivide", o.subdivide}, {"instances", o.instances},
              {"size", {o.width, o.height}}, {"frames", o.frames}, {"embree", have_embree},
              {"configurations", Json::array()}};
  std::string note;
  auto loaded = load_model_or_path(o.model, o.shared, note);
  if (!loaded.ok()) {
    std::fprintf(stderr, "sinew-bench embree: %s\n", loaded.status().message().c_str());
    return 1;
  }
  if (!loaded->has_value()) {
    std::printf("\n%s\n", note.c_str());
    return 0;
  }
  editor::ImportedModel loaded_model = std::move(**loaded);
  if (o.subdivide > 0) {
    auto finer = editor::subdivide(loaded_model, o.subdivide);
    if (!finer.ok()) {
      std::fprintf(stderr, "sinew-bench embree: %s\n", finer.status().message().c_str());
      return 1;
    }
    loaded_model = std::move(*finer);
  }
  const editor::ImportedModel model = std::move(loaded_model);
  editor::InMemoryBake bake;
  {
    JobSystem jobs(*std::max_element(o.threads.begin(), o.threads.end()));
    auto baked = editor::bake_in_memory(model, editor::BakeRequest{}, jobs);
    if (!baked.ok()) {
      std::fprintf(stderr, "sinew-bench embree: %s\n", baked.status().message().c_str());
      return 1;
    }
    bake = std::move(*baked);
  }
  std::printf("  %zu triangles (%d subdivision levels), %zu bones\n", model.mesh.triangle_count(), o.subdivide,
              model.skeleton.joint_count());
  doc["triangles"] = model.mesh.triangle_count();

  int exit_code = 0;
  for (const std::string& clip_name : o.clips) {
    const auto clip = find_clip(model, o.model, clip_name);
    if (!clip.ok()) {
      std::fprintf(stderr, "sinew-bench embree: %s\n", clip.status().message().c_str());
      exit_code = 1;
      continue;
    }
    for (int threads : o.threads) {
      auto result = run_configuration(model, bake.fuzzy.view(), o, clip_name, *clip, threads);
      if (!result.ok()) {
        std::fprintf(stderr, "sinew-bench embree: %s: %s\n", clip_name.c_str(), result.status().message().c_str());
        exit_code = 1;
        continue;
      }
      print_config(*result);
      std::fflush(stdout);
      for (const ContenderResult& c : result->contenders) {
        if (!c.gate.passed()) exit_code = 1;
      }
      doc["configurations"].push_back(config_json(*result));
    }
  }
  std::printf("\n  build = Sinew: boxes + fallback + top level of prepare_frame; Embree: vertex upload +\n"
              "  rtcCommitScene (rebuild or refit); exact: merge + SAH kd build + top level. trace = primary +\n"
              "  shadow rays; total = skinning (shared) + build + trace + shade; medians over the frames.\n"
              "  sinew/this < 1: Sinew is faster. Sinew traces 4x2 packets; Embree rtcIntersect1/rtcOccluded1.\n");
  const std::string load_end = load_average();
  std::printf("  load at the end: %s (1, 5, 15 min)\n", load_end.c_str());
  doc["load_average_end"] = load_end;
  if (!write_output("embree", "--json", o.json_path, doc.dump(2) + "\n")) return 1;
  return exit_code;
}

}  // namespace sinew::bench
