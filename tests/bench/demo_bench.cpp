#include "tests/bench/demo_bench.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "character/pack.h"
#include "editor/import/model_loader.h"
#include "game_demo/character_cost.h"
#include "game_demo/demo_session.h"
#include "game_demo/world.h"
#include "runtime/cli/option_values.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_record.h"

namespace sinew::bench {
namespace {


struct DemoBenchOptions {
  std::vector<int> characters{1, 6, 12};
  float pace_spread = 0.0f;  // each character's own pace (sinew-demo --pace-spread)
  int width = 1024;
  int height = 1024;
  int threads = 2;
  int frames = 30;
  int warmup = 5;
  bool shadows = true;
  bool soft = false;  // sinew-demo --soft: its preset of soft shadows and ambient occlusion
  std::string textures = "on";  // on, off, or both (alternating frames)
  std::string model_path;  // empty: the mannequin
  std::string json_path;
  bool help = false;
};

std::vector<BenchFlag> demo_flags() {
  return {
      {"--characters", "LIST", "character counts to measure (default 1,6,12)"},
      {"--pace-spread", "S", "each character but the player at its own pace in [1 - S, 1 + S], as sinew-demo\n"
                             "--pace-spread (0 to 0.5, default 0)"},
      size_flag("1024x1024"),
      threads_flag("2"),
      frames_flag("measured frames per count (default 30), after"),
      {"--warmup", "N", "unmeasured frames (default 5)"},
      {"--shadows", "on|off", "shadow rays (default on)"},
      {"--soft", "", "soft shadows and ambient occlusion: sinew-demo --soft's preset (default off)"},
      {"--textures", "on|off|both", "textured materials (default on); both: alternate frames off and on"},
      {"--model", "PATH", "glTF or Cal3D character (default the procedural mannequin)"},
      json_flag(),
  };
}

const char* const kDescription = "the game demo's fps and phases\n";

Status read_options(const BenchArgs& parsed, DemoBenchOptions& o) {
  SINEW_RETURN_IF_ERROR(parsed.read("--characters", 1, 256, o.characters));
  if (const auto text = parsed.value("--pace-spread")) {
    SINEW_ASSIGN_OR_RETURN(const double spread, cli::parse_double("--pace-spread", *text, 0.0, 0.5));
    o.pace_spread = static_cast<float>(spread);
  }
  SINEW_RETURN_IF_ERROR(parsed.read_size(8192, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--frames", 1, 100000, o.frames));
  SINEW_RETURN_IF_ERROR(parsed.read("--warmup", 0, 100000, o.warmup));
  SINEW_RETURN_IF_ERROR(parsed.read("--shadows", o.shadows));
  o.soft = parsed.has("--soft");
  SINEW_RETURN_IF_ERROR(parsed.read("--textures", o.textures));
  if (o.textures != "on" && o.textures != "off" && o.textures != "both") {
    return invalid_argument("--textures", o.textures, "expected on, off or both");
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--model", o.model_path));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

struct CountResult {
  int characters = 0;
  std::vector<PhaseSummary> phases;
  double frame_ms = 0.0;  // sum of the phase medians
  demo::CharacterCost per_character;  // from the phase medians
  double rays_per_frame = 0.0;
  std::uint64_t escaped_triangles = 0;
  std::size_t triangles = 0;
  // --textures both: the shade phase's per-frame medians with textures off
  // and on (alternate frames of one session, so both see the same views).
  double shade_off_ms = 0.0, shade_on_ms = 0.0;
  // Over the measured frames: the tracers' work, and the rays it was for.
  rt::TraversalCounters primary, shadow;
};

double per_ray(std::uint64_t work, std::uint64_t rays) {
  return rays > 0 ? static_cast<double>(work) / static_cast<double>(rays) : 0.0;
}

Expected<CountResult> measure(const DemoBenchOptions& o, int characters, JobSystem& jobs) {
  demo::SessionOptions so;
  so.model_path = o.model_path;
  so.characters = characters;
  so.pace_spread = o.pace_spread;
  so.width = o.width;
  so.height = o.height;
  so.shadows = o.shadows;
  if (o.soft) so.soft = demo::soft_preset();
  // The demo loads packs; the bench also takes a source model, imported here.
  std::unique_ptr<demo::DemoSession> session;
  if (o.model_path.empty() || character::is_pack_path(o.model_path)) {
    SINEW_ASSIGN_OR_RETURN(session, demo::DemoSession::create(so, jobs));
  } else {
    SINEW_ASSIGN_OR_RETURN(character::Model model, editor::load_model(o.model_path));
    SINEW_ASSIGN_OR_RETURN(session, demo::DemoSession::create(so, std::move(model), jobs));
  }
  CountResult r;
  r.characters = characters;
  r.triangles = session->bake_info().triangles;
  demo::FollowCamera camera;
  std::uint64_t rays = 0;
  const bool alternate = o.textures == "both";
  session->render_settings().textures = o.textures != "off";
  std::vector<double> shade[2];  // textures off, on
  for (int f = 0; f < o.warmup + o.frames; ++f) {
    if (f == o.warmup) session->timers().clear();
    const demo::PlayerInput input = demo::scripted_input(f);
    camera.yaw = input.camera_yaw;
    if (alternate) session->render_settings().textures = f % 2 == 1;
    SINEW_ASSIGN_OR_RETURN(const demo::FrameReport report, session->frame(1.0f / 30.0f, input, camera, jobs));
    if (f >= o.warmup) {
      shade[session->render_settings().textures ? 1 : 0].push_back(report.render.shade_ms);
      rays += report.render.primary_rays + report.render.shadow_rays + report.render.ao_rays;
      r.escaped_triangles += report.scene.escaped_triangles;
      r.primary += report.render.primary;
      r.shadow += report.render.shadow;
    }
  }
  r.phases = session->timers().summarize();
  r.frame_ms = session->timers().median_total_ms();
  std::vector<std::pair<std::string, double>> medians;
  for (const PhaseSummary& p : r.phases) medians.emplace_back(p.name, p.median_ms);
  r.per_character = demo::per_character_cost(medians, characters);
  r.rays_per_frame = static_cast<double>(rays) / o.frames;
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  r.shade_off_ms = median(shade[0]);
  r.shade_on_ms = median(shade[1]);
  return r;
}

void print_table(const DemoBenchOptions& o, const std::vector<CountResult>& results) {
  if (results.empty()) return;
  std::printf("\n| characters | fps |");
  for (const PhaseSummary& p : results.front().phases) std::printf(" %s |", p.name.c_str());
  std::printf(" frame ms | update ms/character | trace ms/character | M rays/s | escaped tris/frame |\n|---:|---:|");
  for (std::size_t i = 0; i < results.front().phases.size(); ++i) std::printf("---:|");
  std::printf("---:|---:|---:|---:|---:|\n");
  for (const CountResult& r : results) {
    std::printf("| %d | %.1f |", r.characters, r.frame_ms > 0.0 ? 1000.0 / r.frame_ms : 0.0);
    for (const PhaseSummary& p : r.phases) std::printf(" %.2f |", p.median_ms);
    std::printf(" %.1f | %.3f | %.3f | %.1f | %.1f |\n", r.frame_ms, r.per_character.update_ms,
                r.per_character.trace_ms, r.frame_ms > 0.0 ? r.rays_per_frame / (r.frame_ms * 1e3) : 0.0,
                static_cast<double>(r.escaped_triangles) / o.frames);
  }
  std::printf("\n| characters | primary: node visits | objects | triangle tests | shadow: node visits | objects |"
              " triangle tests |\n|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const CountResult& r : results) {
    const rt::TraversalCounters& p = r.primary;
    const rt::TraversalCounters& s = r.shadow;
    std::printf("| %d | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", r.characters, per_ray(p.node_visits, p.rays),
                per_ray(p.object_visits, p.rays), per_ray(p.triangle_tests, p.rays), per_ray(s.node_visits, s.rays),
                per_ray(s.object_visits, s.rays), per_ray(s.triangle_tests, s.rays));
  }
  if (o.textures == "both") {
    std::printf("\n| characters | shade ms, textures off | shade ms, textures on | on / off |\n|---:|---:|---:|---:|\n");
    for (const CountResult& r : results) {
      std::printf("| %d | %.2f | %.2f | %.3f |\n", r.characters, r.shade_off_ms, r.shade_on_ms,
                  r.shade_off_ms > 0.0 ? r.shade_on_ms / r.shade_off_ms : 0.0);
    }
  }
  std::printf("\nPhase columns are per-frame medians in ms over %d frames after %d warm-up frames; fps = 1000 /"
              " their sum. Per character: the update phases (animation, skinning, boxes, fallback, top level) and the"
              " trace phases (primary, shadow, ambient occlusion) over the character count. M rays/s counts primary,"
              " shadow and ambient occlusion rays over"
              " the whole frame time. The second table is the"
              " tracers' work per ray (render/renderer.h TraversalCounters) over the same frames.\n",
              o.frames, o.warmup);
}

}  // namespace

int run_demo_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("demo", kDescription, demo_flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const DemoBenchOptions& o = *parsed;
  JobSystem jobs(o.threads);
  BenchRecord record("demo", command_line, jobs.thread_count());
  std::printf("  %dx%d, shadows %s, soft lighting %s, pace spread %.2f\n", o.width, o.height,
              o.shadows ? "on" : "off", o.soft ? "on" : "off", static_cast<double>(o.pace_spread));
  Json& doc = record.doc();
  doc["size"] = {o.width, o.height};
  doc["shadows"] = o.shadows;
  doc["soft"] = o.soft;
  doc["textures"] = o.textures;
  doc["pace_spread"] = o.pace_spread;
  doc["counts"] = Json::array();
  std::vector<CountResult> results;
  for (int characters : o.characters) {
    std::fprintf(stderr, "measuring %d characters...\n", characters);
    auto r = measure(o, characters, jobs);
    if (!r.ok()) {
      record.fail(std::to_string(characters) + " characters", r.status());
      return record.exit_code();
    }
    results.push_back(std::move(*r));
  }
  std::printf("model: %s (%zu triangles)\n", o.model_path.empty() ? "mannequin (procedural)" : o.model_path.c_str(),
              results.empty() ? std::size_t{0} : results.front().triangles);
  print_table(o, results);
  for (const CountResult& r : results) {
    Json phases = Json::object();
    for (const PhaseSummary& p : r.phases) phases[p.name] = p.median_ms;
    doc["counts"].push_back({{"characters", r.characters}, {"fps", r.frame_ms > 0.0 ? 1000.0 / r.frame_ms : 0.0},
                             {"frame_ms", r.frame_ms}, {"phases_ms", phases},
                             {"per_character_ms", {{"update", r.per_character.update_ms},
                                                   {"trace", r.per_character.trace_ms}}},
                             {"rays_per_frame", r.rays_per_frame}});
    if (o.textures == "both") {
      doc["counts"].back()["shade_ms_textures_off"] = r.shade_off_ms;
      doc["counts"].back()["shade_ms_textures_on"] = r.shade_on_ms;
    }
  }
  return record.finish(o.json_path);
}

}  // namespace sinew::bench
