#include "tests/bench/structures_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/brute_force_gate.h"
#include "tests/bench/table_numbers.h"
#include "tests/bench/walk_measure.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

constexpr int kGateStride = 7;

struct Options {
  std::vector<int> levels{0, 1, 2, 3, 4};  // Cally's subdivision levels
  // The other models, relative to SHARED/content (absent ones are noted and skipped).
  std::vector<std::string> models{"cal3d/paladin/paladin.cfg", "cal3d/skeleton/skeleton.cfg",
                                  "gltf/CesiumMan/CesiumMan.glb", "gltf/BrainStem/BrainStem.glb"};
  int clusters = 16;  // K of the clustered structure
  int frames = 10;
  int width = 1024;
  int height = 1024;
  int threads = 2;
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  std::string markdown_path;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      quick_flag("Cally levels 0,2, CesiumMan, 3 frames, 256x256"),
      {"--levels", "LIST", "Cally's subdivision levels (default 0,1,2,3,4; none: skip Cally)"},
      {"--models", "LIST", "other models under SHARED/content (default cal3d/paladin/paladin.cfg,\n"
                           "cal3d/skeleton/skeleton.cfg, gltf/CesiumMan/CesiumMan.glb, gltf/BrainStem/BrainStem.glb;\n"
                           "none: skip them)"},
      {"--clusters", "K", "pose-space clusters a bone in the clustered structure (default 16)"},
      {"--frames", "N", "frames at 30 fps through the model's walk or first clip (default 10)"},
      size_flag("1024x1024"),
      threads_flag("2"),
      shared_flag(),
      json_flag(),
      markdown_flag(),
  };
}

const char* const kDescription =
    "the paper's one kd-tree a bone against pose-space clusters and BVH bone trees: pack, bake,\n"
    "fuzzy area, update, work per ray, frame time, per model and Cally subdivision level\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  if (parsed.has("--quick")) {
    o.levels = {0, 2};
    o.models = {"gltf/CesiumMan/CesiumMan.glb"};
    o.frames = 3;
    o.width = o.height = 256;
  }
  if (const auto text = parsed.value("--levels")) {
    if (*text == "none") {
      o.levels.clear();
    } else {
      SINEW_ASSIGN_OR_RETURN(o.levels, parse_int_list("--levels", *text, 0, editor::kMaxSubdivisionLevels));
    }
  }
  if (const auto text = parsed.value("--models")) {
    if (*text == "none") {
      o.models.clear();
    } else {
      SINEW_ASSIGN_OR_RETURN(o.models, cli::parse_list("--models", *text));
    }
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--clusters", 1, rt::kMaxPoseClusters, o.clusters));
  SINEW_RETURN_IF_ERROR(parsed.read("--frames", 1, 100000, o.frames));
  SINEW_RETURN_IF_ERROR(parsed.read_size(16384, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  SINEW_RETURN_IF_ERROR(parsed.read("--markdown", o.markdown_path));
  return {};
}

struct Subject {
  std::string name;
  character::Model model;
  std::size_t clip = 0;  // the walk, or the first clip
};

struct Row {
  std::string model;
  std::size_t triangles = 0;
  int clusters_per_bone = 0;  // 0: one tree a bone (the paper's, with kd-trees)
  rt::BoneTreeKind trees = rt::BoneTreeKind::kKdTree;
  std::uint32_t cluster_count = 0;
  std::size_t pack_bytes = 0;
  double bake_s = 0.0;
  double fuzzy_area = 0.0;    // x the rest boxes', full trees
  double cluster_area = 0.0;  // x the rest boxes', averaged over each bone's clusters
  double update_ms = 0.0;     // median skinning + boxes + fallback + top level
  double primary_tests = 0.0, primary_visits = 0.0;  // per primary ray
  double shadow_tests = 0.0, shadow_visits = 0.0;    // per shadow ray
  double frame_ms = 0.0;      // median prepare_frame + render
  std::size_t frame_bytes = 0;  // what an instance's frame holds after the last frame
  GateResult gate;
};

// The structures each model is measured with, in table order.
struct Structure {
  int clusters;  // 0, or Options::clusters
  rt::BoneTreeKind trees;
};

std::vector<Structure> structures(const Options& o) {
  return {{0, rt::BoneTreeKind::kKdTree},
          {o.clusters, rt::BoneTreeKind::kKdTree},
          {0, rt::BoneTreeKind::kBvh},
          {o.clusters, rt::BoneTreeKind::kBvh}};
}

std::string structure_name(int clusters, rt::BoneTreeKind trees) {
  const std::string kind = trees == rt::BoneTreeKind::kBvh ? "BVH" : "kd-tree";
  return clusters == 0 ? "one " + kind + " a bone" : std::to_string(clusters) + " clusters, " + kind + "s";
}

Expected<Row> measure(const Subject& s, Structure structure, const Options& o, JobSystem& jobs,
                      WalkFraming& framing) {
  const int clusters = structure.clusters;
  Row row;
  row.model = s.name;
  row.triangles = s.model.mesh.triangle_count();
  row.clusters_per_bone = clusters;
  row.trees = structure.trees;
  character::BakeRequest request;
  request.fuzzy.pose_clusters = static_cast<std::uint32_t>(clusters);
  request.fuzzy.fine_mesh_clusters = false;  // 0 is one tree a bone at every size
  request.fuzzy.bone_trees = structure.trees;
  const Clock::time_point bake_start = Clock::now();
  SINEW_ASSIGN_OR_RETURN(const character::InMemoryBake bake, character::bake_in_memory(s.model, request, jobs));
  row.bake_s = ms_since(bake_start) / 1000.0;
  const rt::FuzzyBakeStats& bake_stats = bake.fuzzy.stats;
  row.cluster_count = bake_stats.cluster_count;
  const double rest = bake_stats.rest_area;
  row.fuzzy_area = rest > 0.0 ? bake_stats.fuzzy_area / rest : 0.0;
  row.cluster_area = rest > 0.0 ? (clusters > 0 ? bake_stats.cluster_fuzzy_area : bake_stats.fuzzy_area) / rest : 0.0;
  {
    character::PackContents contents;
    contents.model = &s.model;
    contents.fuzzy = &bake.fuzzy;
    contents.pose_space.desc = request.pose_space;
    contents.provenance.source_name = s.name;
    SINEW_ASSIGN_OR_RETURN(const std::vector<std::byte> bytes, character::serialize_pack(contents));
    row.pack_bytes = bytes.size();
  }

  WalkRequest walk;
  walk.frames = o.frames;
  walk.width = o.width;
  walk.height = o.height;
  walk.gate_stride = kGateStride;
  SINEW_ASSIGN_OR_RETURN(const WalkMeasure walked,
                         measure_walk(s.model, bake.fuzzy.view(), s.model.clips[s.clip], walk, jobs, framing));
  const rt::TraversalCounters& primary = walked.primary;
  const rt::TraversalCounters& shadow = walked.shadow;
  row.gate = walked.gate;
  const auto per_ray = [](std::uint64_t n, std::uint64_t rays) {
    return rays > 0 ? static_cast<double>(n) / static_cast<double>(rays) : 0.0;
  };
  row.primary_tests = per_ray(primary.triangle_tests, primary.rays);
  row.primary_visits = per_ray(primary.node_visits, primary.rays);
  row.shadow_tests = per_ray(shadow.triangle_tests, shadow.rays);
  row.shadow_visits = per_ray(shadow.node_visits, shadow.rays);
  row.update_ms = walked.phase_ms("skinning") + walked.phase_ms("boxes") + walked.phase_ms("fallback") +
                  walked.phase_ms("top level");
  row.frame_ms = walked.median_frame_ms();
  row.frame_bytes = walked.frame_bytes;
  return row;
}

Json row_json(const Row& r) {
  return {{"model", r.model},
          {"triangles", r.triangles},
          {"clusters_per_bone", r.clusters_per_bone},
          {"bone_trees", r.trees == rt::BoneTreeKind::kBvh ? "bvh" : "kd"},
          {"clusters", r.cluster_count},
          {"pack_bytes", r.pack_bytes},
          {"bake_s", r.bake_s},
          {"fuzzy_area_ratio", r.fuzzy_area},
          {"cluster_area_ratio", r.cluster_area},
          {"update_ms", r.update_ms},
          {"primary_tests_per_ray", r.primary_tests},
          {"primary_visits_per_ray", r.primary_visits},
          {"shadow_tests_per_ray", r.shadow_tests},
          {"shadow_visits_per_ray", r.shadow_visits},
          {"frame_ms", r.frame_ms},
          {"frame_bytes", r.frame_bytes},
          {"gate_checked", r.gate.checked},
          {"gate_mismatched", r.gate.mismatched},
          {"gate_grazes", r.gate.grazes}};
}

std::string markdown(const std::vector<Row>& rows, const std::vector<std::string>& notes, const Options& o,
                     const std::string& command, const std::string& cpu, const std::string& date) {
  std::string md;
  const auto line = [&md](const std::string& s) { md += s + "\n"; };
  line("## Structures compared: one tree a bone, pose-space clusters, kd-trees and BVHs");
  line("");
  line("Measured by `" + command + "` on " + cpu + ", " + std::to_string(o.threads) + " threads, " + date +
       " (commit " + git_commit() + "). Each model is baked in memory over every clip's key poses and 30 Hz poses "
       "(the default pose space) four times: with the paper's one fuzzy kd-tree a bone (`--pose-clusters 0 "
       "--bone-trees kd`), with " + std::to_string(o.clusters) + " pose-space clusters a bone (docs/RAYTRACE.md "
       "\"Pose-space clusters\"), and both again with BVH bone trees (`--bone-trees bvh`, the default; docs/RAYTRACE.md "
       "\"Bone trees: kd-tree or BVH\"). `pack` "
       "is the character pack the editor would write, `bake` the in-memory bake's wall time, `area` the fuzzy box "
       "area over the rest pose's (for clusters: full trees → averaged over each bone's clusters), `update` the median "
       "of skinning with the escape check, bone boxes, fallback and top level, `tests`/`visits` the triangle tests "
       "and tree node visits per primary and per shadow ray, `frame` the median of prepare_frame + render over " +
       std::to_string(o.frames) + " frames of the walk (or the first clip) at 30 Hz, " + std::to_string(o.width) +
       "x" + std::to_string(o.height) + ", shadows from a point light; `frame MB` what one instance's frame holds "
       "(skinned vertices, escape flags, bone frames and boxes, cluster choices). The first frame of each is "
       "checked against brute force (every " + std::to_string(kGateStride) + "th pixel; a configuration that "
       "differs is FAILED and its numbers left out). Per character the pack is "
       "the memory; per instance, the frame.");
  line("");
  line("| model | triangles | structure | pack MB | bake s | area | update ms | primary tests / visits | shadow "
       "tests / visits | frame ms | frame MB | brute force |");
  line("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
  for (const Row& r : rows) {
    const std::string structure = structure_name(r.clusters_per_bone, r.trees);
    if (!r.gate.passed()) {  // its numbers would describe a wrong image
      line("| " + r.model + " | " + std::to_string(r.triangles) + " | " + structure + " | | | | | | | | | FAILED: " +
           std::to_string(r.gate.mismatched) + " of " + std::to_string(r.gate.checked) + " px differ |");
      continue;
    }
    const std::string area = r.clusters_per_bone == 0 ? fixed(r.fuzzy_area, 2)
                                                      : fixed(r.fuzzy_area, 2) + " → " + fixed(r.cluster_area, 2);
    line("| " + r.model + " | " + std::to_string(r.triangles) + " | " + structure + " | " +
         fixed(static_cast<double>(r.pack_bytes) / 1e6, 1) + " | " + fixed(r.bake_s, 1) + " | " + area + " | " +
         fixed(r.update_ms, 2) + " | " + fixed(r.primary_tests, 2) + " / " + fixed(r.primary_visits, 2) + " | " +
         fixed(r.shadow_tests, 2) + " / " + fixed(r.shadow_visits, 2) + " | " + fixed(r.frame_ms, 2) + " | " +
         fixed(static_cast<double>(r.frame_bytes) / 1e6, 1) + " | " + std::to_string(r.gate.checked) + " px ok" +
         (r.gate.grazes > 0 ? ", " + std::to_string(r.gate.grazes) + (r.gate.grazes == 1 ? " edge graze" : " edge grazes") : "") + " |");
  }
  for (const std::string& note : notes) line("\n" + note);
  return md;
}

}  // namespace

int run_structures_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("structures", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;
  const std::string cpu = cpu_model();
  const std::string date = utc_date();
  print_bench_header("structures", command_line, std::to_string(o.threads), cpu, date);

  std::vector<std::string> notes;
  std::vector<Subject> subjects;
  if (!o.levels.empty()) {
    std::string note;
    auto cally = load_model("cally", o.shared, note);
    if (!cally.ok()) {
      std::fprintf(stderr, "sinew-bench structures: cally: %s\n", cally.status().message().c_str());
      return 1;
    }
    if (!cally->has_value()) {
      notes.push_back(note);
    } else {
      for (const int level : o.levels) {
        auto finer = editor::subdivide(**cally, level);
        if (!finer.ok()) {
          std::fprintf(stderr, "sinew-bench structures: subdivide: %s\n", finer.status().message().c_str());
          return 1;
        }
        const auto walk = find_walk_clip(*finer, "cally");
        subjects.push_back({level == 0 ? "Cally" : "Cally level " + std::to_string(level), std::move(*finer),
                            walk.ok() ? *walk : 0});
      }
    }
  }
  for (const std::string& relative : o.models) {
    const std::string path = o.shared + "/content/" + relative;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      notes.push_back(relative + " skipped: " + path + " not found (pass --shared DIR)");
      continue;
    }
    std::string note;
    auto model = load_model_or_path(path, o.shared, note);
    if (!model.ok() || !model->has_value()) {
      std::fprintf(stderr, "sinew-bench structures: %s: %s\n", path.c_str(),
                   model.ok() ? note.c_str() : model.status().message().c_str());
      return 1;
    }
    if ((*model)->clips.empty()) {
      notes.push_back(relative + " skipped: it has no clip to animate");
      continue;
    }
    const auto walk = find_walk_clip(**model, relative);
    subjects.push_back({std::filesystem::path(relative).stem().string(), std::move(**model), walk.ok() ? *walk : 0});
  }
  for (const std::string& n : notes) std::printf("  note: %s\n", n.c_str());

  JobSystem jobs(o.threads);
  std::vector<Row> rows;
  int exit_code = 0;
  std::printf("  %-16s %8s %9s %8s %7s %15s %9s %15s %15s %9s %8s\n", "model", "tris", "structure", "pack MB",
              "bake s", "area", "update", "primary t/v", "shadow t/v", "frame ms", "frame MB");
  for (const Subject& s : subjects) {
    WalkFraming framing;  // one camera and brute-force reference for every structure
    for (const Structure& structure : structures(o)) {
      const int k = structure.clusters;
      const bool bvh = structure.trees == rt::BoneTreeKind::kBvh;
      auto row = measure(s, structure, o, jobs, framing);
      if (!row.ok()) {
        std::fprintf(stderr, "sinew-bench structures: %s, %s: %s\n", s.name.c_str(),
                     structure_name(k, structure.trees).c_str(), row.status().message().c_str());
        exit_code = 1;
        continue;
      }
      if (!row->gate.passed()) exit_code = 1;
      std::printf("  %-16s %8zu %9s %8.1f %7.1f %7.2f -> %5.2f %9.2f %7.2f / %5.2f %7.2f / %5.2f %9.2f %8.1f%s\n",
                  s.name.c_str(), row->triangles,
                  ((k == 0 ? std::string(bvh ? "1" : "paper") : std::to_string(k) + " cl") + (bvh ? " bvh" : "")).c_str(),
                  static_cast<double>(row->pack_bytes) / 1e6, row->bake_s, row->fuzzy_area, row->cluster_area,
                  row->update_ms, row->primary_tests, row->primary_visits, row->shadow_tests, row->shadow_visits,
                  row->frame_ms, static_cast<double>(row->frame_bytes) / 1e6,
                  row->gate.passed() ? "" : "  FAILED brute force");
      std::fflush(stdout);
      rows.push_back(*row);
    }
  }

  Json doc;
  doc["command"] = command_line;
  doc["cpu"] = cpu;
  doc["date"] = date;
  doc["commit"] = git_commit();
  doc["threads"] = o.threads;
  doc["frames"] = o.frames;
  doc["size"] = {o.width, o.height};
  doc["clusters_per_bone"] = o.clusters;
  doc["rows"] = Json::array();
  doc["failed"] = Json::array();
  for (const Row& r : rows) {
    if (r.gate.passed()) {
      doc["rows"].push_back(row_json(r));
    } else {
      doc["failed"].push_back({{"model", r.model}, {"clusters_per_bone", r.clusters_per_bone},
                               {"bone_trees", r.trees == rt::BoneTreeKind::kBvh ? "bvh" : "kd"},
                               {"mismatched", r.gate.mismatched}, {"checked", r.gate.checked}});
    }
  }
  doc["notes"] = notes;
  if (!write_output("structures", "--json", o.json_path, doc.dump(2) + "\n")) return 1;
  if (!write_output("structures", "--markdown", o.markdown_path, markdown(rows, notes, o, command_line, cpu, date))) {
    return 1;
  }
  return exit_code;
}

}  // namespace sinew::bench
