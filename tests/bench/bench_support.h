// Small pieces the sinew-bench programs share: the machine and the date for
// their header lines, and the models they measure.
#pragma once

#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <chrono>

#include "character/bake.h"
#include "character/framing.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/cal3d_importer.h"
#include "editor/import/model_loader.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/core/expected.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::bench {

// The CPU's model name from /proc/cpuinfo, "unknown" elsewhere.
// The renderer's default packets in words, e.g. "16×16-pixel packets of
// 256 rays" (a packet is a square region; 8 rays are one 4×2 block).
inline std::string packet_words() {
  const int rays = rt::RenderSettings{}.packet_rays;
  int side = 1;
  while (side * side < rays) ++side;
  if (side * side != rays) return std::to_string(rays) + "-ray packets";
  const std::string s = std::to_string(side);
  return s + "×" + s + "-pixel packets of " + std::to_string(rays) + " rays";
}

inline std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) break;
    const std::size_t start = line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? std::string() : line.substr(start);
  }
  return "unknown";
}

inline std::string utc_date() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

// The short commit of the working directory's git checkout, "unknown"
// outside one (or without git).
inline std::string git_commit() {
  std::FILE* pipe = popen("git rev-parse --short HEAD 2>/dev/null", "r");
  if (!pipe) return "unknown";
  char text[64] = {};
  const bool read = std::fgets(text, sizeof text, pipe) != nullptr;
  pclose(pipe);
  std::string commit = read ? text : "";
  while (!commit.empty() && (commit.back() == '\n' || commit.back() == '\r')) commit.pop_back();
  return commit.empty() ? "unknown" : commit;
}

// The 1, 5 and 15 minute load averages (/proc/loadavg): a busy machine's
// timings are noisy, and the table should say so.
inline std::string load_average() {
  std::ifstream in("/proc/loadavg");
  double one = 0.0, five = 0.0, fifteen = 0.0;
  if (!(in >> one >> five >> fifteen)) return "unknown";
  char text[64];
  std::snprintf(text, sizeof text, "%.2f, %.2f, %.2f", one, five, fifteen);
  return text;
}

// The lines every benchmark table starts with: what ran, where, when.
inline void print_bench_header(const char* name, const std::string& command_line, const std::string& threads,
                               const std::string& cpu, const std::string& date) {
  std::printf("sinew-bench %s\n", name);
  std::printf("  command: %s\n", command_line.c_str());
  std::printf("  cpu:     %s (%d hardware threads)\n", cpu.c_str(), JobSystem::hardware_threads());
  std::printf("  threads: %s\n", threads.c_str());
  std::printf("  isa:     %s\n", std::string(build_isa()).c_str());
  std::printf("  date:    %s\n", date.c_str());
  std::printf("  commit:  %s\n", git_commit().c_str());
  std::printf("  load:    %s (1, 5, 15 min, at start)\n", load_average().c_str());
}

// Writes a benchmark's --json or --markdown output (nothing for an empty
// path). False, with a message naming the flag and the file, when the file
// cannot be written.
inline bool write_output(const char* bench, const char* flag, const std::string& path, const std::string& text) {
  if (path.empty()) return true;
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) {
    std::fprintf(stderr, "sinew-bench %s: cannot write %s %s\n", bench, flag, path.c_str());
    return false;
  }
  return true;
}

// The error of an Expected whose value the caller does not need.
template <typename T>
Status status_of(const Expected<T>& result) {
  return result.ok() ? Status{} : result.status();
}

// "1,2,4": the inverse of parse_int_list, for headers and tables.
inline std::string join_ints(const std::vector<int>& values) {
  std::string out;
  for (int v : values) out += (out.empty() ? "" : ",") + std::to_string(v);
  return out;
}

using cli::parse_int_list;  // "1,6,12"

// "mannequin" (procedural) or "cally" (from SHARED/content/cal3d/cally).
// Cally is optional content: a missing file is a note, not a failure, so a
// benchmark still runs on a machine with only the procedural mannequin.
inline Expected<std::optional<character::Model>> load_model(const std::string& name, const std::string& shared,
                                                          std::string& note) {
  if (name == "mannequin") {
    SINEW_ASSIGN_OR_RETURN(character::Model model, content::make_mannequin());
    return std::optional<character::Model>(std::move(model));
  }
  const std::string cfg = shared + "/content/cal3d/cally/cally.cfg";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(cfg, ec)) {
    note = "cally skipped: " + cfg + " not found (pass --shared DIR)";
    return std::optional<character::Model>();
  }
  SINEW_ASSIGN_OR_RETURN(character::Model model, editor::import_cal3d(cfg));
  return std::optional<character::Model>(std::move(model));
}

// "mannequin", "cally", or the path of any model the tools read (glTF,
// Cal3D .cfg, or a .pack, whose model is used and baked in memory).
inline Expected<std::optional<character::Model>> load_model_or_path(const std::string& name,
                                                                 const std::string& shared, std::string& note) {
  if (name == "mannequin" || name == "cally") return load_model(name, shared, note);
  SINEW_ASSIGN_OR_RETURN(character::Model model, editor::load_model(name));
  return std::optional<character::Model>(std::move(model));
}

// The index of the clip called `clip`.
inline Expected<std::size_t> find_clip(const character::Model& model, const std::string& name,
                                       const std::string& clip) {
  for (std::size_t i = 0; i < model.clips.size(); ++i) {
    if (model.clips[i].name() == clip) return i;
  }
  std::string known;
  for (const anim::Clip& c : model.clips) known += (known.empty() ? "" : ", ") + c.name();
  return make_error(ErrorCode::kNotFound, name, "clip", clip,
                    "the model has no clip of that name (its clips: " + (known.empty() ? "none" : known) + ")");
}

// The index of the clip named "walk".
inline Expected<std::size_t> find_walk_clip(const character::Model& model, const std::string& name) {
  return find_clip(model, name, "walk");
}

// The staged benchmark scene: `instances` copies of one character placed in
// a row or a grid on a ground quad, as the render command places them
// (character/framing.h).
struct BenchStage {
  rt::Scene scene;
  std::vector<std::uint32_t> ids;
  std::vector<Affine3> placements;
  rt::StaticMeshDesc ground;
  Aabb rest;
  int up = 1;
};

inline Status stage_instances(const character::Model& model, const rt::FuzzyCharacterView& fuzzy,
                              int instances, BenchStage& stage,
                              character::Layout layout = character::Layout::kRow) {
  stage.rest = character::rest_bounds(model);
  stage.up = character::up_axis_of(stage.rest);
  SINEW_ASSIGN_OR_RETURN(const std::uint32_t character, stage.scene.add_character(model.mesh, fuzzy));
  for (int i = 0; i < instances; ++i) {
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t id, stage.scene.add_instance(character));
    stage.ids.push_back(id);
    stage.placements.push_back(character::instance_placement(stage.rest, i, instances, layout));
  }
  stage.ground = character::ground_plane_for(stage.rest, instances, layout);
  const auto ground = stage.scene.add_static_mesh(stage.ground);
  return ground.ok() ? Status{} : ground.status();
}

// Poses every instance of `stage` at `seconds` through `clip` (instance i
// offset by character::instance_time_offset(i)); prepare_frame comes next.
inline Status pose_instances(const character::Model& model, const anim::Clip& clip, double seconds,
                             BenchStage& stage) {
  for (std::size_t i = 0; i < stage.ids.size(); ++i) {
    const double t = seconds + character::instance_time_offset(static_cast<int>(i));
    SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> bones,
                           character::clip_skinning(model, clip, t, stage.placements[i]));
    SINEW_RETURN_IF_ERROR(stage.scene.set_bones(stage.ids[i], bones));
  }
  return {};
}

// The exact SAH kd-tree contender: `exact` (an empty scene) gets one static
// mesh of `fuzzy_scene`'s skinned world triangles (instance after instance,
// so triangle i*T + t is instance i's triangle t) and the ground, and is
// prepared. Its tree is built as the bone trees are (FuzzyBakeOptions::kd:
// the SAH the renderer's packets are tuned for), so fuzzy against exact
// compares the structures, not two builds. Returns the build time of the
// skinned mesh's tree in ms.
inline Expected<double> build_exact_scene(const rt::Scene& fuzzy_scene, const SkinnedMesh& mesh,
                                          const rt::StaticMeshDesc& ground, JobSystem& jobs, rt::Scene& exact) {
  rt::StaticMeshDesc skinned;
  for (const rt::InstanceFrame& instance : fuzzy_scene.instances()) {
    const auto base = static_cast<std::uint32_t>(skinned.positions.size());
    skinned.positions.insert(skinned.positions.end(), instance.positions.begin(), instance.positions.end());
    for (const auto& t : mesh.triangles) skinned.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  const auto build_start = std::chrono::steady_clock::now();
  const auto added = exact.add_static_mesh(std::move(skinned), rt::FuzzyBakeOptions{}.kd);
  if (!added.ok()) return added.status();
  const double build_ms = ms_since(build_start);
  const auto ground_added = exact.add_static_mesh(ground);
  if (!ground_added.ok()) return ground_added.status();
  const auto prepared = exact.prepare_frame(rt::FrameOptions{}, jobs);
  if (!prepared.ok()) return prepared.status();
  return build_ms;
}

}  // namespace sinew::bench
