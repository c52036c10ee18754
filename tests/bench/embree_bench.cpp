#include "tests/bench/embree_bench.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_record.h"
#include "tests/bench/brute_force_gate.h"
// Always included for EmbreeMode and EmbreeWidth, which the options name;
// the tracer itself is only linked (and called) when Embree was found.
#include "runtime/memory/line_aligned.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/embree_tracer.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kFramesPerSecond = 30.0;


// --- options -------------------------------------------------------------------

// The Embree modes as --embree-modes names them and as the table labels them.
struct ModeSpec {
  EmbreeMode mode;
  const char* key;
  const char* label;
};
constexpr ModeSpec kModes[] = {{EmbreeMode::kRebuildLow, "low", "LOW rebuild"},
                               {EmbreeMode::kRefit, "refit", "refit"},
                               {EmbreeMode::kRebuildMedium, "medium", "MEDIUM rebuild"}};

const ModeSpec& mode_spec(EmbreeMode mode) {
  for (const ModeSpec& m : kModes) {
    if (m.mode == mode) return m;
  }
  return kModes[0];
}

// Rays per Embree call: what --embree-widths lists and the JSON records.
int lanes_of(EmbreeWidth width) {
  switch (width) {
    case EmbreeWidth::k1: return 1;
    case EmbreeWidth::k4: return 4;
    case EmbreeWidth::k8: return 8;
    case EmbreeWidth::k16: return 16;
  }
  return 1;
}

struct Options {
  int width = 1024;
  int height = 1024;
  int frames = 120;
  std::vector<int> threads{1, 2};
  std::vector<std::string> clips{"walk"};
  std::string model = "cally";
  int instances = 1;
  character::Layout layout = character::Layout::kRow;  // --layout
  int subdivide = 0;  // subdivision levels applied to the model (Table 2's larger meshes)
  int check_stride = 7;
  // Every (mode, width) pair is a row of its own: which width suits Embree
  // best depends on the mode, the mesh and the machine, so all are measured
  // and Sinew is compared with the best.
  std::vector<EmbreeMode> embree_modes{EmbreeMode::kRebuildLow, EmbreeMode::kRefit, EmbreeMode::kRebuildMedium};
  std::vector<EmbreeWidth> embree_widths{std::begin(kEmbreeWidths), std::end(kEmbreeWidths)};
  // Soft shadows and ambient occlusion, sized by the character's height
  // (its posed extent along its up axis).
  float light_radius = 0.0f;  // the point light's sphere radius, in heights
  int shadow_samples = 4;
  int ao_rays = 0;
  float ao_length = 0.5f;  // in heights
  // The Embree flag of the area-light and ambient occlusion rays: each is a
  // row of its own when both are asked for.
  std::vector<bool> secondary_coherent{true, false};
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      quick_flag("256x256, 30 frames, 1 thread, Embree refit at widths 1,16 only"),
      {"--model", "M", "cally (default), mannequin, or a .gltf/.glb/.cfg/.pack path"},
      {"--instances", "N", "character instances (default 1)"},
      {"--layout", "row|grid", "how the instances stand, as sinew-editor render --layout (default row)"},
      frames_flag("frames at 30 fps through each clip (default 120)"),
      {"--clips", "LIST", "clips to animate, e.g. walk,tornado_kick (default walk)"},
      {"--clip", "NAME", "one clip to animate (instead of --clips)"},
      size_flag("1024x1024"),
      thread_list_flag("1,2"),
      {"--embree-modes", "LIST",
       "Embree modes: low (LOW rebuild), refit, medium (MEDIUM rebuild)\n(default low,refit,medium)"},
      {"--embree-widths", "LIST",
       "rays per Embree call: 1 (rtcIntersect1/rtcOccluded1) or 4, 8, 16\n"
       "(coherent packets); every mode runs at every width (default 1,4,8,16)"},
      {"--subdivide", "L", "subdivide the model L times first (each level: 4x the triangles)"},
      {"--light-radius", "H", "the point light is a sphere of radius H x the character's height (default 0)"},
      {"--shadow-samples", "S", "shadow rays per hit towards an area light (default 4)"},
      {"--ao-rays", "A", "ambient occlusion rays per hit (default 0: none)"},
      {"--ao-length", "H", "their length, x the character's height (default 0.5)"},
      {"--embree-secondary", "coherent|incoherent|both",
       "Embree's flag for area-light and ambient occlusion rays;\nboth: a row each (default both)"},
      {"--check-stride", "N", "brute-force check every Nth pixel of the first frame (default 7)"},
      shared_flag(),
      json_flag(),
  };
}

const char* const kDescription = "Sinew vs Embree 3 (rebuild LOW/MEDIUM, refit) vs exact kd\n";

// "low,refit,medium": each mode once.
Expected<std::vector<EmbreeMode>> parse_modes(const std::string& text) {
  namespace cli = sinew::cli;
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::string> items, cli::parse_list("--embree-modes", text));
  std::vector<EmbreeMode> modes;
  for (const std::string& item : items) {
    SINEW_ASSIGN_OR_RETURN(const int index, cli::parse_choice("--embree-modes", item, {"low", "refit", "medium"}));
    const EmbreeMode mode = kModes[index].mode;
    if (std::find(modes.begin(), modes.end(), mode) != modes.end()) {
      return invalid_argument("--embree-modes", item, "listed twice");
    }
    modes.push_back(mode);
  }
  return modes;
}

// "1,4,8,16": each width once, of the four Embree has calls for.
Expected<std::vector<EmbreeWidth>> parse_widths(const std::string& text) {
  SINEW_ASSIGN_OR_RETURN(const std::vector<int> lanes, parse_int_list("--embree-widths", text, 1, 16));
  std::vector<EmbreeWidth> widths;
  for (const int n : lanes) {
    const auto* found = std::find_if(std::begin(kEmbreeWidths), std::end(kEmbreeWidths),
                                     [n](EmbreeWidth w) { return lanes_of(w) == n; });
    if (found == std::end(kEmbreeWidths)) {
      return invalid_argument("--embree-widths", std::to_string(n), "expected 1, 4, 8 or 16");
    }
    if (std::find(widths.begin(), widths.end(), *found) != widths.end()) {
      return invalid_argument("--embree-widths", std::to_string(n), "listed twice");
    }
    widths.push_back(*found);
  }
  return widths;
}

Status read_options(const BenchArgs& parsed, Options& o) {
  namespace cli = sinew::cli;
  if (parsed.has("--quick")) {  // explicit flags below still override
    o.width = o.height = 256;
    o.frames = 30;
    o.threads = {1};
    // The cheapest Embree mode at its two ends, single rays and the widest
    // packets: twelve Embree rows would triple the quick run.
    o.embree_modes = {EmbreeMode::kRefit};
    o.embree_widths = {EmbreeWidth::k1, EmbreeWidth::k16};
  }
  SINEW_RETURN_IF_ERROR(parsed.read_size(16384, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read("--frames", 1, 100000, o.frames));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  if (parsed.has("--clip") && parsed.has("--clips")) {
    return invalid_argument("--clip", *parsed.value("--clip"), "give --clip or --clips, not both");
  }
  if (const auto text = parsed.value("--clip")) o.clips = {*text};
  if (const auto text = parsed.value("--clips")) {
    SINEW_ASSIGN_OR_RETURN(o.clips, cli::parse_list("--clips", *text));
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--model", o.model));
  SINEW_RETURN_IF_ERROR(parsed.read("--instances", 1, 256, o.instances));
  if (const auto text = parsed.value("--layout")) {
    SINEW_ASSIGN_OR_RETURN(const int layout, cli::parse_choice("--layout", *text, {"row", "grid"}));
    o.layout = static_cast<character::Layout>(layout);
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--subdivide", 0, editor::kMaxSubdivisionLevels, o.subdivide));
  SINEW_RETURN_IF_ERROR(parsed.read("--check-stride", 1, 1 << 20, o.check_stride));
  SINEW_RETURN_IF_ERROR(parsed.read("--light-radius", 0.0, 10.0, o.light_radius));
  SINEW_RETURN_IF_ERROR(parsed.read("--shadow-samples", 1, rt::kMaxSamples, o.shadow_samples));
  SINEW_RETURN_IF_ERROR(parsed.read("--ao-rays", 0, rt::kMaxSamples, o.ao_rays));
  SINEW_RETURN_IF_ERROR(parsed.read("--ao-length", 0.001, 10.0, o.ao_length));
  if (const auto text = parsed.value("--embree-secondary")) {
    SINEW_ASSIGN_OR_RETURN(const int which,
                           cli::parse_choice("--embree-secondary", *text, {"coherent", "incoherent", "both"}));
    o.secondary_coherent = which == 0 ? std::vector<bool>{true} : which == 1 ? std::vector<bool>{false}
                                                                             : std::vector<bool>{true, false};
  }
  if (const auto text = parsed.value("--embree-modes")) {
    SINEW_ASSIGN_OR_RETURN(o.embree_modes, parse_modes(*text));
  }
  if (const auto text = parsed.value("--embree-widths")) {
    SINEW_ASSIGN_OR_RETURN(o.embree_widths, parse_widths(*text));
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

// --- contenders ----------------------------------------------------------------

enum class Kind : std::uint8_t { kSinew, kEmbree, kExact };

// One row of the table: Sinew, Embree in one (mode, width) pair, or the
// exact kd-tree.
struct Contender {
  Kind kind = Kind::kSinew;
  EmbreeMode mode = EmbreeMode::kRefit;  // kEmbree only
  EmbreeWidth width = EmbreeWidth::k1;   // kEmbree only
  bool secondary_coherent = true;        // kEmbree only: its area-light and ambient occlusion rays' flag
  bool secondary = false;                // whether the frame has such rays (the label says the flag)
};

// "rtcIntersect8": the Embree call the width uses (its name lives in the
// tracer, which is only linked when Embree was found).
std::string width_label(EmbreeWidth width) {
#ifdef SINEW_HAVE_EMBREE
  return embree_width_name(width);
#else
  return "x" + std::to_string(lanes_of(width));
#endif
}

// "LOW rebuild rtcIntersect8": the mode and the width, as the summary names
// the best Embree row.
std::string embree_label(const Contender& c) {
  return std::string(mode_spec(c.mode).label) + " " + width_label(c.width) +
         (c.secondary ? (c.secondary_coherent ? " coherent" : " incoherent") : "");
}

std::string contender_name(const Contender& c) {
  switch (c.kind) {
    case Kind::kSinew: return kSinewContender;
    case Kind::kEmbree: return "embree " + embree_label(c);
    case Kind::kExact: return "exact SAH kd rebuild";
  }
  return "?";
}

struct ContenderResult {
  Contender which;
  PhaseTimers timers;  // "build", "trace primary", "trace shadow", "trace", "shade", "total"
  GateResult gate;
  std::uint64_t primary_hits = 0;  // last frame
  std::uint64_t shadow_rays = 0;   // last frame
  std::uint64_t ao_rays = 0;       // last frame
};

struct ConfigResult {
  std::string clip;
  int threads = 0;
  PhaseTimers shared;  // "animation", "skinning"
  std::vector<ContenderResult> contenders;  // Sinew first
};

// One frame's numbers of one contender.
struct FrameSample {
  double build_ms = 0.0;
  double primary_ms = 0.0;
  double shadow_ms = 0.0;
  double ao_ms = 0.0;
  double shade_ms = 0.0;
  std::uint64_t primary_hits = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t ao_rays = 0;
};

void record(ContenderResult& r, const FrameSample& s, double skinning_ms) {
  r.timers.record("build", s.build_ms);
  r.timers.record("trace primary", s.primary_ms);
  r.timers.record("trace shadow", s.shadow_ms);
  r.timers.record("trace ao", s.ao_ms);
  r.timers.record("trace", s.primary_ms + s.shadow_ms + s.ao_ms);
  r.timers.record("shade", s.shade_ms);
  r.timers.record("total", skinning_ms + s.build_ms + s.primary_ms + s.shadow_ms + s.ao_ms + s.shade_ms);
  r.primary_hits = s.primary_hits;
  r.shadow_rays = s.shadow_rays;
  r.ao_rays = s.ao_rays;
}

double phase(const PhaseTimers& timers, std::string_view name) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == name) return s.median_ms;
  }
  return 0.0;
}

// The passing Embree row of lowest median total among those `keep` accepts;
// nullptr when there is none.
template <class Keep>
const ContenderResult* best_embree_where(const ConfigResult& r, Keep keep) {
  const ContenderResult* best = nullptr;
  for (const ContenderResult& c : r.contenders) {
    if (c.which.kind != Kind::kEmbree || !c.gate.passed() || !keep(c.which)) continue;
    if (!best || phase(c.timers, "total") < phase(best->timers, "total")) best = &c;
  }
  return best;
}

const ContenderResult* best_embree(const ConfigResult& r) {
  return best_embree_where(r, [](const Contender&) { return true; });
}

const ContenderResult* best_embree_of_mode(const ConfigResult& r, EmbreeMode mode) {
  return best_embree_where(r, [mode](const Contender& c) { return c.mode == mode; });
}

// The frame's fixed inputs shared by every contender.
struct FrameContext {
  const character::Model* model = nullptr;
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
  s.ao_ms = stats.trace_ao_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  s.ao_rays = stats.ao_rays;
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
  s.ao_ms = stats.trace_ao_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  s.ao_rays = stats.ao_rays;
  if (gate) {
    SINEW_ASSIGN_OR_RETURN(std::vector<Hit> hits, render_primary_hits(exact, c.camera, c.settings, *c.jobs));
    map_exact_ids(c.stage->scene, c.model->mesh.triangles.size(), hits);
    *gate_out = gate->check(hits);
  }
  return s;
}

#ifdef SINEW_HAVE_EMBREE
// One Embree row's frame: the BVH brought up to date and the frame rendered
// at the row's width; on the gated frame, the hits of the same width.
Expected<FrameSample> run_embree(const FrameContext& c, EmbreeTracer& tracer, const Contender& row,
                                 std::span<std::uint8_t> color, const BruteForceGate* gate, GateResult* gate_out) {
  FrameSample s;
  const EmbreeWidth width = row.width;
  SINEW_ASSIGN_OR_RETURN(s.build_ms, tracer.update(c.stage->scene));
  SINEW_ASSIGN_OR_RETURN(const EmbreeRenderStats stats, tracer.render(c.stage->scene, c.camera, c.settings, color, {},
                                                                      *c.jobs, width, row.secondary_coherent));
  s.primary_ms = stats.trace_primary_ms;
  s.shadow_ms = stats.trace_shadow_ms;
  s.ao_ms = stats.trace_ao_ms;
  s.shade_ms = stats.shade_ms;
  s.primary_hits = stats.primary_hits;
  s.shadow_rays = stats.shadow_rays;
  s.ao_rays = stats.ao_rays;
  if (gate) {
    std::vector<Hit> hits(static_cast<std::size_t>(c.camera.width()) * static_cast<std::size_t>(c.camera.height()));
    SINEW_RETURN_IF_ERROR(status_of(tracer.render(c.stage->scene, c.camera, c.settings, {}, hits, *c.jobs, width)));
    *gate_out = gate->check(hits);
  }
  return s;
}
#endif

// Sinew, then every Embree (mode, width) pair asked for (mode by mode),
// then the exact kd-tree.
std::vector<Contender> contenders(const Options& o) {
  std::vector<Contender> order{{Kind::kSinew}};
#ifdef SINEW_HAVE_EMBREE
  const bool secondary = o.light_radius > 0.0f || o.ao_rays > 0;
  for (const EmbreeMode mode : o.embree_modes) {
    for (const EmbreeWidth width : o.embree_widths) {
      if (!secondary) {
        order.push_back({Kind::kEmbree, mode, width});
        continue;
      }
      for (const bool coherent : o.secondary_coherent) order.push_back({Kind::kEmbree, mode, width, coherent, true});
    }
  }
#else
  (void)o;
#endif
  order.push_back({Kind::kExact});
  return order;
}

Expected<ConfigResult> run_configuration(const character::Model& model, const rt::FuzzyCharacterView& fuzzy,
                                         const Options& o, const std::string& clip_name, std::size_t clip,
                                         int threads) {
  JobSystem jobs(threads);
  BenchStage stage;
  SINEW_RETURN_IF_ERROR(stage_instances(model, fuzzy, o.instances, stage, o.layout));

  ConfigResult result;
  result.clip = clip_name;
  result.threads = threads;
  const std::vector<Contender> order = contenders(o);
  for (const Contender& c : order) result.contenders.push_back(ContenderResult{c, {}, {}, 0, 0, 0});

#ifdef SINEW_HAVE_EMBREE
  // One tracer (one Embree device and scene) per mode, shared by its widths:
  // each row still uploads, rebuilds or refits and is timed for it before
  // its own render, so a row never traces a BVH it did not pay for, and
  // there are as many devices (thread pools) as before.
  std::array<std::unique_ptr<EmbreeTracer>, std::size(kModes)> tracers;
  for (const EmbreeMode mode : o.embree_modes) {
    SINEW_ASSIGN_OR_RETURN(tracers[static_cast<std::size_t>(mode)], EmbreeTracer::create(mode, threads));
  }
#endif

  // Line-aligned, as a host would give it: both contenders' shading streams its rows.
  LineAlignedVector<std::uint8_t> color(4 * static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height));
  FrameContext ctx;
  ctx.model = &model;
  ctx.stage = &stage;
  ctx.jobs = &jobs;
  ctx.settings.shadows = true;
  ctx.settings.light.kind = rt::Light::Kind::kPoint;
  ctx.settings.shadow_samples = o.shadow_samples;
  ctx.settings.ao_rays = o.ao_rays;
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
      const Aabb posed = character::posed_bounds(stage.scene);
      ctx.settings.light.position = character::default_light(posed, stage.up);
      const float height = posed.upper[stage.up] - posed.lower[stage.up];
      ctx.settings.light.radius = o.light_radius * height;
      ctx.settings.ao_radius = o.ao_length * height;
      SINEW_ASSIGN_OR_RETURN(ctx.camera, rt::PinholeCamera::create(character::default_camera(posed, stage.up, o.width,
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
      switch (r.which.kind) {
        case Kind::kSinew: {
          SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats,
                                 sinew_renderer.render(stage.scene, ctx.camera, ctx.settings, ctx.color, jobs));
          sample = sinew_sample(prepare, stats);
          if (check) {
            SINEW_ASSIGN_OR_RETURN(const std::vector<Hit> hits, render_primary_hits(stage.scene, ctx.camera, ctx.settings, *ctx.jobs));
            r.gate = check->check(hits);
          }
          break;
        }
        case Kind::kExact: {
          SINEW_ASSIGN_OR_RETURN(sample, run_exact(ctx, exact_renderer, check, &r.gate));
          break;
        }
        case Kind::kEmbree: {
#ifdef SINEW_HAVE_EMBREE
          SINEW_ASSIGN_OR_RETURN(sample, run_embree(ctx, *tracers[static_cast<std::size_t>(r.which.mode)], r.which,
                                                    color, check, &r.gate));
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

double fps_of(double total_ms) { return total_ms > 0.0 ? 1000.0 / total_ms : 0.0; }

// The table's name cell: the best Embree row is marked.
std::string row_label(const ContenderResult& c, const ContenderResult* best) {
  return contender_name(c.which) + (&c == best ? " (best Embree)" : "");
}

// Per mode, the width that ran it fastest (the modes asked for, in order).
void print_best_widths(const ConfigResult& r) {
  std::string line;
  for (const ModeSpec& m : kModes) {
    const bool ran = std::any_of(r.contenders.begin(), r.contenders.end(), [&](const ContenderResult& c) {
      return c.which.kind == Kind::kEmbree && c.which.mode == m.mode;
    });
    if (!ran) continue;
    const ContenderResult* best = best_embree_of_mode(r, m.mode);
    char text[160];
    if (best) {
      std::snprintf(text, sizeof text, "%s %s (total %.3f ms)", m.label, width_label(best->which.width).c_str(),
                    phase(best->timers, "total"));
    } else {
      std::snprintf(text, sizeof text, "%s none (every width failed its brute-force check)", m.label);
    }
    line += (line.empty() ? "" : "; ") + std::string(text);
  }
  if (!line.empty()) std::printf("best width per Embree mode: %s\n", line.c_str());
}

// The summary under the table: the best Embree row against Sinew.
void print_best_summary(const ConfigResult& r) {
  const bool any_embree = std::any_of(r.contenders.begin(), r.contenders.end(),
                                      [](const ContenderResult& c) { return c.which.kind == Kind::kEmbree; });
  if (!any_embree) return;
  const ContenderResult* best = best_embree(r);
  if (!best) {
    std::printf("best Embree: none (every Embree row failed its brute-force check)\n");
    return;
  }
  const ContenderResult& sinew = r.contenders.front();
  const double total = phase(best->timers, "total"), trace = phase(best->timers, "trace");
  std::printf("best Embree: %s: total %.3f ms (%.2f fps), trace %.3f ms; ", embree_label(best->which).c_str(), total,
              fps_of(total), trace);
  if (!sinew.gate.passed()) {
    std::printf("Sinew FAILED its brute-force check\n");
    return;
  }
  const double sinew_total = phase(sinew.timers, "total"), sinew_trace = phase(sinew.timers, "trace");
  std::printf("Sinew total %.3f ms (%.2f fps), trace %.3f ms; Sinew/best total %s, trace %s\n", sinew_total,
              fps_of(sinew_total), sinew_trace, ratio_text(sinew_total, total).c_str(),
              ratio_text(sinew_trace, trace).c_str());
}

// Rays a second of each kind, the ray counts of the last frame over the
// median trace time of the kind.
double mrays_per_s(std::uint64_t rays, double ms) { return ms > 0.0 ? static_cast<double>(rays) / (ms * 1e3) : 0.0; }

void print_rays_by_kind(const ConfigResult& r) {
  const ContenderResult* best = best_embree(r);
  for (const ContenderResult* c : {&r.contenders.front(), best}) {
    if (!c) continue;
    std::printf("%s: shadow %llu rays at %.1f Mrays/s", c == best ? "best Embree" : "Sinew",
                static_cast<unsigned long long>(c->shadow_rays),
                mrays_per_s(c->shadow_rays, phase(c->timers, "trace shadow")));
    if (c->ao_rays > 0) {
      std::printf(", ambient occlusion %llu rays at %.1f Mrays/s", static_cast<unsigned long long>(c->ao_rays),
                  mrays_per_s(c->ao_rays, phase(c->timers, "trace ao")));
    }
    std::printf(" (of a thread-second: trace ms are wall times)\n");
  }
}

void print_config(const ConfigResult& r) {
  std::printf("\n### clip %s, %d thread%s\n\n", r.clip.c_str(), r.threads, r.threads == 1 ? "" : "s");
  std::printf("shared per frame (median ms): animation %.3f, skinning %.3f (Sinew's, identical for all)\n\n",
              phase(r.shared, "animation"), phase(r.shared, "skinning"));
  std::printf("| contender | build/refit ms | primary ms | shadow ms | ao ms | trace ms | shade ms | total ms | "
              "sinew/this build | sinew/this trace | sinew/this total | brute force |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  const ContenderResult& sinew = r.contenders.front();
  const ContenderResult* best = best_embree(r);
  for (const ContenderResult& c : r.contenders) {
    const std::string check = std::to_string(c.gate.checked) + " px ok" +
                              (c.gate.grazes ? ", " + std::to_string(c.gate.grazes) + " edge grazes" : "");
    if (!c.gate.passed()) {
      std::printf("| %s | FAILED brute-force check (%llu of %llu sampled pixels differ) | | | | | | | | | | FAILED |\n",
                  contender_name(c.which).c_str(), static_cast<unsigned long long>(c.gate.mismatched),
                  static_cast<unsigned long long>(c.gate.checked));
      continue;
    }
    const double b = phase(c.timers, "build"), t = phase(c.timers, "trace"), tot = phase(c.timers, "total");
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %s | %s | %s |\n",
                row_label(c, best).c_str(), b, phase(c.timers, "trace primary"), phase(c.timers, "trace shadow"),
                phase(c.timers, "trace ao"), t, phase(c.timers, "shade"), tot,
                ratio_text(phase(sinew.timers, "build"), b).c_str(), ratio_text(phase(sinew.timers, "trace"), t).c_str(),
                ratio_text(phase(sinew.timers, "total"), tot).c_str(), check.c_str());
  }
  std::printf("\n");
  print_best_widths(r);
  print_best_summary(r);
  print_rays_by_kind(r);
}

// A ratio for the JSON: null when either side is missing.
Json ratio_json(double sinew, double other) {
  return sinew > 0.0 && other > 0.0 ? Json(sinew / other) : Json(nullptr);
}

// The Embree row's mode and width, as the report reads them.
void add_embree_keys(const Contender& c, Json& entry) {
  entry["mode"] = mode_spec(c.mode).key;
  entry["mode_name"] = mode_spec(c.mode).label;
  entry["width"] = lanes_of(c.width);
  entry["width_name"] = width_label(c.width);
  entry["label"] = embree_label(c);
}

// One row: its medians under plain names (the "phases" object keeps every
// sample statistic) and Sinew's ratios against it.
Json contender_json(const ContenderResult& c, const ContenderResult& sinew, const ContenderResult* best) {
  const char* kinds[] = {"sinew", "embree", "exact"};
  Json entry = {{"name", contender_name(c.which)}, {"kind", kinds[static_cast<int>(c.which.kind)]}};
  if (c.which.kind == Kind::kEmbree) {
    add_embree_keys(c.which, entry);
    entry["best_embree"] = &c == best;
  }
  entry["brute_force"] = {{"passed", c.gate.passed()},
                          {"checked", c.gate.checked},
                          {"mismatched", c.gate.mismatched},
                          {"edge_grazes", c.gate.grazes}};
  if (!c.gate.passed()) return entry;
  entry["phases"] = Json::parse(c.timers.json(), nullptr, false);
  const double total = phase(c.timers, "total");
  entry["median_ms"] = {{"build", phase(c.timers, "build")},
                        {"primary", phase(c.timers, "trace primary")},
                        {"shadow", phase(c.timers, "trace shadow")},
                        {"ao", phase(c.timers, "trace ao")},
                        {"trace", phase(c.timers, "trace")},
                        {"shade", phase(c.timers, "shade")},
                        {"total", total}};
  entry["fps"] = fps_of(total);
  const bool sinew_ok = sinew.gate.passed();
  entry["sinew_over_this"] = {
      {"build", sinew_ok ? ratio_json(phase(sinew.timers, "build"), phase(c.timers, "build")) : Json(nullptr)},
      {"trace", sinew_ok ? ratio_json(phase(sinew.timers, "trace"), phase(c.timers, "trace")) : Json(nullptr)},
      {"total", sinew_ok ? ratio_json(phase(sinew.timers, "total"), total) : Json(nullptr)}};
  entry["primary_hits"] = c.primary_hits;
  entry["shadow_rays"] = c.shadow_rays;
  entry["ao_rays"] = c.ao_rays;
  entry["shadow_mrays_per_s"] = mrays_per_s(c.shadow_rays, phase(c.timers, "trace shadow"));
  entry["ao_mrays_per_s"] = mrays_per_s(c.ao_rays, phase(c.timers, "trace ao"));
  return entry;
}

// The best Embree row and Sinew against it, as the summary line prints
// them; null when no Embree row ran or passed.
Json best_json(const ConfigResult& r, const ContenderResult* best) {
  if (!best) return nullptr;
  const ContenderResult& sinew = r.contenders.front();
  const double total = phase(best->timers, "total"), trace = phase(best->timers, "trace");
  Json doc = {{"name", contender_name(best->which)}};
  add_embree_keys(best->which, doc);
  doc["total_ms"] = total;
  doc["fps"] = fps_of(total);
  doc["trace_ms"] = trace;
  if (sinew.gate.passed()) {
    const double sinew_total = phase(sinew.timers, "total"), sinew_trace = phase(sinew.timers, "trace");
    doc["sinew_total_ms"] = sinew_total;
    doc["sinew_fps"] = fps_of(sinew_total);
    doc["sinew_trace_ms"] = sinew_trace;
    doc["sinew_over_best_total"] = ratio_json(sinew_total, total);
    doc["sinew_over_best_trace"] = ratio_json(sinew_trace, trace);
  }
  return doc;
}

Json config_json(const ConfigResult& r) {
  const ContenderResult* best = best_embree(r);
  Json doc = {{"clip", r.clip},
              {"threads", r.threads},
              {"shared", Json::parse(r.shared.json(), nullptr, false)},
              {"contenders", Json::array()}};
  for (const ContenderResult& c : r.contenders) {
    doc["contenders"].push_back(contender_json(c, r.contenders.front(), best));
  }
  // The fastest width of each mode that ran, by name: the rows above.
  Json by_mode = Json::array();
  for (const ModeSpec& m : kModes) {
    if (const ContenderResult* b = best_embree_of_mode(r, m.mode)) by_mode.push_back(best_json(r, b));
  }
  doc["best_embree_by_mode"] = std::move(by_mode);
  doc["best_embree"] = best_json(r, best);
  return doc;
}

std::vector<int> widths_of(const std::vector<EmbreeWidth>& widths) {
  std::vector<int> lanes;
  for (const EmbreeWidth w : widths) lanes.push_back(lanes_of(w));
  return lanes;
}

std::vector<std::string> mode_keys(const std::vector<EmbreeMode>& modes) {
  std::vector<std::string> keys;
  for (const EmbreeMode m : modes) keys.emplace_back(mode_spec(m).key);
  return keys;
}

std::string join_modes(const std::vector<EmbreeMode>& modes) {
  std::string out;
  for (const std::string& key : mode_keys(modes)) out += (out.empty() ? "" : ",") + key;
  return out;
}

}  // namespace

int run_embree_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("embree", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;
  BenchRecord record("embree", command_line, o.threads);
#ifdef SINEW_HAVE_EMBREE
  const bool have_embree = true;
#else
  const bool have_embree = false;
  std::printf("  Embree not found: its columns are skipped\n");
#endif
  std::printf("  model %s, %d instance%s in a %s, %dx%d, %d frames at 30 fps per clip, point light, shadows on,\n"
              "  diffuse shading; brute-force check of every %dth pixel of the first frame\n",
              o.model.c_str(), o.instances, o.instances == 1 ? "" : "s",
              character::kLayoutNames[static_cast<int>(o.layout)], o.width, o.height, o.frames, o.check_stride);
  if (o.light_radius > 0.0f) {
    std::printf("  sphere light of radius %.2f x the character's height, %d shadow samples per hit\n", static_cast<double>(o.light_radius),
                o.shadow_samples);
  }
  if (o.ao_rays > 0) {
    std::printf("  %d ambient occlusion rays per hit, %.2f x the character's height long\n", o.ao_rays, static_cast<double>(o.ao_length));
  }
  if (have_embree) {
    std::printf("  Embree modes %s at widths %s: every pair is a row\n", join_modes(o.embree_modes).c_str(),
                join_ints(widths_of(o.embree_widths)).c_str());
  }
  std::fflush(stdout);

  Json& doc = record.doc();
  doc.update(Json{{"model", o.model},
                  {"subdivide", o.subdivide},
                  {"instances", o.instances},
                  {"layout", character::kLayoutNames[static_cast<int>(o.layout)]},
                  {"size", {o.width, o.height}},
                  {"frames", o.frames},
                  {"embree", have_embree},
                  {"embree_modes", mode_keys(o.embree_modes)},
                  {"embree_widths", widths_of(o.embree_widths)},
                  {"light_radius_heights", o.light_radius},
                  {"shadow_samples", o.shadow_samples},
                  {"ao_rays", o.ao_rays},
                  {"ao_length_heights", o.ao_length},
                  {"configurations", Json::array()}});
  std::string note;
  auto loaded = load_model_or_path(o.model, o.shared, note);
  if (!loaded.ok()) {
    record.fail("", loaded.status());
    return record.exit_code();
  }
  if (!loaded->has_value()) {
    record.note(note);
    return record.finish(o.json_path);
  }
  character::Model loaded_model = std::move(**loaded);
  if (o.subdivide > 0) {
    auto finer = editor::subdivide(loaded_model, o.subdivide);
    if (!finer.ok()) {
      record.fail("--subdivide", finer.status());
      return record.exit_code();
    }
    loaded_model = std::move(*finer);
  }
  const character::Model model = std::move(loaded_model);
  character::InMemoryBake bake;
  {
    JobSystem jobs(*std::max_element(o.threads.begin(), o.threads.end()));
    auto baked = character::bake_in_memory(model, character::BakeRequest{}, jobs);
    if (!baked.ok()) {
      record.fail("bake", baked.status());
      return record.exit_code();
    }
    bake = std::move(*baked);
  }
  std::printf("  %zu triangles (%d subdivision levels), %zu bones\n", model.mesh.triangle_count(), o.subdivide,
              model.skeleton.joint_count());
  doc["triangles"] = model.mesh.triangle_count();
  // Which structure Sinew's rows trace: the bake's default (pose-space
  // clusters from rt::kFineMeshTriangles, docs/RAYTRACE.md).
  const rt::FuzzyBakeStats& bake_stats = bake.fuzzy.stats;
  const double rest = bake_stats.rest_area > 0.0 ? bake_stats.rest_area : 1.0;
  const char* const kind = bake.fuzzy.tree_kind == rt::BoneTreeKind::kBvh ? "BVHs" : "kd-trees";
  if (bake_stats.cluster_count > 0) {
    std::printf("  Sinew's trees: %s, up to %u pose-space clusters a bone (%u in all), fuzzy area %.2fx the rest "
                "boxes' averaged over each bone's clusters (%.2fx with one tree a bone)\n",
                kind, bake_stats.clusters_per_bone, bake_stats.cluster_count, bake_stats.cluster_fuzzy_area / rest,
                bake_stats.fuzzy_area / rest);
  } else {
    std::printf("  Sinew's trees: %s, one a bone (no pose-space clusters), fuzzy area %.2fx the rest boxes'\n", kind,
                bake_stats.fuzzy_area / rest);
  }
  doc["bone_trees"] = bake.fuzzy.tree_kind == rt::BoneTreeKind::kBvh ? "bvh" : "kd";
  doc["pose_clusters"] = bake_stats.cluster_count;
  doc["clusters_per_bone"] = bake_stats.clusters_per_bone;

  std::vector<std::string> best_rows;  // the best Embree row of each configuration, for the note
  for (const std::string& clip_name : o.clips) {
    const auto clip = find_clip(model, o.model, clip_name);
    if (!clip.ok()) {
      record.fail("", clip.status());
      continue;
    }
    for (int threads : o.threads) {
      auto result = run_configuration(model, bake.fuzzy.view(), o, clip_name, *clip, threads);
      if (!result.ok()) {
        record.fail(clip_name, result.status());
        continue;
      }
      print_config(*result);
      std::fflush(stdout);
      for (const ContenderResult& c : result->contenders) {
        if (!c.gate.passed()) record.mark_failed();
      }
      if (const ContenderResult* best = best_embree(*result)) {
        best_rows.push_back(clip_name + ", " + std::to_string(threads) + " thread" + (threads == 1 ? "" : "s") +
                            ": " + embree_label(best->which));
      }
      doc["configurations"].push_back(config_json(*result));
    }
  }
  std::printf("\n  build = Sinew: boxes + fallback + top level of prepare_frame; Embree: vertex upload +\n"
              "  rtcCommitScene (rebuild or refit); exact: merge + SAH kd build + top level. trace = primary +\n"
              "  shadow rays; total = skinning (shared) + build + trace + shade; medians over the frames.\n"
              "  sinew/this < 1: Sinew is faster. Sinew traces %s culled cell by cell\n"
              "  (traverse/large_packet.h) after a tile cull of the top level (render/stages/tile_stages.h). Embree is\n"
              "  shown at every width run: 1 = rtcIntersect1/rtcOccluded1,\n"
              "  4/8/16 = rtcIntersectN/rtcOccludedN packets with RTC_INTERSECT_CONTEXT_FLAG_COHERENT; the best\n"
              "  Embree row (lowest median total) is marked, and Sinew/best compares Sinew with it.\n",
              packet_words().c_str());
  for (const std::string& row : best_rows) std::printf("  best Embree, %s\n", row.c_str());
  const std::string load_end = load_average();
  std::printf("  load at the end: %s (1, 5, 15 min)\n", load_end.c_str());
  doc["load_average_end"] = load_end;
  return record.finish(o.json_path);
}

}  // namespace sinew::bench
