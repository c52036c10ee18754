// sinew-bench paper: the paper's Tables 1 and 2 (Günther et al. 2006,
// section 4) measured on Sinew, each paper row printed beside Sinew's.
//
// Table 2: Cally subdivided (editor::subdivide) level by level; per level
// the bake's preprocessing time, split as the paper splits it, and the fps
// of rendering the walk clip at 1024x1024 with diffuse shading, primary
// rays only and with shadow rays. Our levels multiply the triangle count by
// 4 where the paper's rows grow by about 3, so rows at the paper's counts
// are interpolated log-log between our neighbouring levels (marked).
//
// Table 1: for Cally and the mannequin, the four pose spaces with the
// paper's sample counts; fuzzy area, triangles per leaf and the fps of the
// rest pose from one viewpoint per model.
//
// The benchmarks' rule holds throughout (docs/BENCHMARKS.md): a
// configuration whose first frame fails the brute-force check
// (brute_force_gate.h) is printed as FAILED with no numbers, and the exit
// code is 1.
#include "tests/bench/paper_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "animation/joint_limits.h"
#include "animation/pose.h"
#include "animation/pose_space.h"
#include "character/bake.h"
#include "character/framing.h"
#include "content/mannequin/mannequin.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/jobs/job_system.h"
#include "runtime/memory/line_aligned.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_record.h"
#include "tests/bench/brute_force_gate.h"
#include "tests/bench/table_numbers.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;


// --- the paper's numbers ---------------------------------------------------------

struct PaperTable2Row {
  int triangles;
  double sampling_s;
  double build_s;
  double fps;  // one 2.4 GHz Opteron core, 1024x1024, simple diffuse shader
};
constexpr PaperTable2Row kPaperTable2Cally[] = {
    {3000, 0.63, 0.65, 9.5}, {10000, 1.80, 2.28, 7.1}, {30000, 5.21, 8.77, 5.7},
    {90000, 16.4, 34.5, 3.6}, {271000, 50.4, 150.0, 2.0},
};

struct PaperTable1Row {
  const char* mode;
  int samples;
  double fuzzy_area;  // absolute, in the UT 2003 scene's units
  double tris_per_leaf;
  double fps;
};
constexpr PaperTable1Row kPaperTable1[] = {
    {"arbitrary", 1000, 747e3, 4.1, 7.7},
    {"limits", 245, 580e3, 3.4, 10.2},
    {"clips", 124, 552e3, 3.2, 11.6},
    {"clip", 62, 515e3, 3.1, 12.0},
};

// --- options ----------------------------------------------------------------------

// The source tree's joint limits for Cally.
std::string default_cally_limits() { return std::string(SINEW_SOURCE_DIR) + "/content/limits/cally.json"; }

struct Options {
  bool quick = false;
  std::vector<int> tables{1, 2};
  std::vector<int> levels{0, 1, 2, 3, 4};
  std::vector<int> threads{1, 2};
  int frames = 8;
  int width = 1024;
  int height = 1024;
  int samples = 0;  // Table 2's pose space: 0 = every key time + 30 Hz
  int check_stride = 7;
  std::string shared = SINEW_SHARED_DIR;
  std::string cally_limits = default_cally_limits();
  std::string json_path;
  std::string markdown_path;
  bool clip_ranges = false;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      quick_flag("levels 0,1,2, 3 frames, 1 thread"),
      {"--tables", "LIST", "which of the paper's tables to measure (default 1,2)"},
      {"--levels", "LIST", "Table 2's subdivision levels of Cally (default 0,1,2,3,4)"},
      thread_list_flag("1,2"),
      frames_flag("frames timed per configuration, median taken (default 8)"),
      size_flag("1024x1024"),
      {"--samples", "N", "Table 2's pose samples (default: all clips, key times + 30 Hz)"},
      {"--check-stride", "N", "brute-force check every Nth pixel of each first frame (default 7)"},
      shared_flag(),
      {"--limits", "FILE", "Cally's joint limits (default content/limits/cally.json)"},
      json_flag(),
      markdown_flag(),
      {"--clip-ranges", "", "print the Euler ranges of Cally's clip key poses per joint, then exit"},
  };
}

const char* const kDescription = "the paper's Tables 1 and 2 on Cally\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  if (parsed.has("--quick")) {  // explicit flags below still override
    o.quick = true;
    o.levels = {0, 1, 2};
    o.frames = 3;
    o.threads = {1};  // the paper's single core
  }
  SINEW_RETURN_IF_ERROR(parsed.read("--tables", 1, 2, o.tables));
  SINEW_RETURN_IF_ERROR(parsed.read("--levels", 0, editor::kMaxSubdivisionLevels, o.levels));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--frames", 1, 100000, o.frames));
  SINEW_RETURN_IF_ERROR(parsed.read_size(16384, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read("--samples", 1, anim::kMaxPoseSamples, o.samples));
  SINEW_RETURN_IF_ERROR(parsed.read("--check-stride", 1, 1 << 20, o.check_stride));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--limits", o.cally_limits));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  SINEW_RETURN_IF_ERROR(parsed.read("--markdown", o.markdown_path));
  o.clip_ranges = parsed.has("--clip-ranges");
  std::sort(o.levels.begin(), o.levels.end());
  o.levels.erase(std::unique(o.levels.begin(), o.levels.end()), o.levels.end());
  return {};
}

// --- measuring one scene ----------------------------------------------------------

struct FpsPair {
  double primary = 0.0;          // shadows off, as the paper's Table 2
  double primary_shadows = 0.0;  // one shadow ray per lit hit
  // Per primary ray of the last primary-only frame: the work the fuzzy
  // area predicts, free of the machine's noise.
  double triangle_tests_per_ray = 0.0;
  double node_visits_per_ray = 0.0;
};
using FpsByThreads = std::vector<std::pair<int, FpsPair>>;

struct GateReport {
  GateResult result;
  int stride = 0;
  double reference_ms = 0.0;  // the brute-force reference's cost
};

// Poses the stage for frame f (set_bones only; prepare_frame is timed apart).
using PoseFrame = std::function<Status(int frame, BenchStage& stage)>;

// The view every frame of one configuration shares, framed (as the render
// command frames it) on the stage's first posed frame, and the gate's
// verdict on that frame.
struct FirstFrame {
  rt::PinholeCamera camera;
  rt::RenderSettings settings;
  GateReport gate;
};

Expected<FirstFrame> frame_and_gate(BenchStage& stage, const PoseFrame& pose, int width, int height, int stride,
                                    int threads) {
  JobSystem jobs(threads);
  SINEW_RETURN_IF_ERROR(pose(0, stage));
  SINEW_RETURN_IF_ERROR(status_of(stage.scene.prepare_frame(rt::FrameOptions{}, jobs)));
  FirstFrame first;
  const Aabb posed = character::posed_bounds(stage.scene);
  first.settings.light.kind = rt::Light::Kind::kPoint;
  first.settings.light.position = character::default_light(posed, stage.up);
  SINEW_ASSIGN_OR_RETURN(first.camera,
                         rt::PinholeCamera::create(character::default_camera(posed, stage.up, width, height), width,
                                                   height));
  const Clock::time_point start = Clock::now();
  const BruteForceGate gate(stage.scene, first.camera, stride);
  first.gate.reference_ms = ms_since(start);
  first.gate.stride = stride;
  SINEW_ASSIGN_OR_RETURN(const std::vector<Hit> hits, render_primary_hits(stage.scene, first.camera, first.settings, jobs));
  first.gate.result = gate.check(hits);
  return first;
}

// Frame time = pose (set_bones) + prepare_frame + render, the whole frame a
// host pays; fps = 1000 / median over the frames. Primary-only and shadowed
// renders alternate frame by frame so machine noise falls on both.
Expected<FpsPair> measure_fps(BenchStage& stage, const FirstFrame& view, const PoseFrame& pose, int frames,
                              int threads) {
  JobSystem jobs(threads);
  const int w = view.camera.width(), h = view.camera.height();
  LineAlignedVector<std::uint8_t> color(4 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  rt::FrameBuffers buffers;
  buffers.width = w;
  buffers.height = h;
  buffers.color_rgba8 = color;
  rt::Renderer renderer;
  std::vector<double> primary_ms, shadowed_ms;
  rt::TraversalCounters last_primary;
  for (int f = 0; f < frames; ++f) {
    for (const bool shadows : {false, true}) {
      rt::RenderSettings settings = view.settings;
      settings.shadows = shadows;
      const Clock::time_point start = Clock::now();
      SINEW_RETURN_IF_ERROR(pose(f, stage));
      SINEW_RETURN_IF_ERROR(status_of(stage.scene.prepare_frame(rt::FrameOptions{}, jobs)));
      SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats,
                             renderer.render(stage.scene, view.camera, settings, buffers, jobs));
      (shadows ? shadowed_ms : primary_ms).push_back(ms_since(start));
      if (!shadows) last_primary = stats.primary;
    }
  }
  FpsPair fps;
  const double p = median_of(primary_ms), s = median_of(shadowed_ms);
  fps.primary = p > 0.0 ? 1000.0 / p : 0.0;
  fps.primary_shadows = s > 0.0 ? 1000.0 / s : 0.0;
  if (last_primary.rays > 0) {
    const auto rays = static_cast<double>(last_primary.rays);
    fps.triangle_tests_per_ray = static_cast<double>(last_primary.triangle_tests) / rays;
    fps.node_visits_per_ray = static_cast<double>(last_primary.node_visits) / rays;
  }
  return fps;
}

// --- Table 2 ------------------------------------------------------------------------

struct Table2Row {
  int level = 0;  // -1 for interpolated rows
  std::size_t triangles = 0;
  bool interpolated = false;
  bool failed = false;  // brute-force check failed: no numbers
  GateReport gate;
  std::uint32_t samples = 0;
  double pose_sampling_ms = 0.0;
  double fuzzy_sampling_ms = 0.0;
  double assignment_ms = 0.0;
  double build_ms = 0.0;
  double sampling_s = 0.0;  // pose sampling + fuzzy box sampling + bone assignment
  double build_s = 0.0;     // the bone trees
  double tris_per_leaf = 0.0;
  FpsByThreads fps;
};

anim::PoseSpaceDesc table2_pose_space(const Options& o) {
  anim::PoseSpaceDesc space = character::default_pose_space();
  if (o.samples > 0) space.samples = o.samples;
  return space;
}

Expected<Table2Row> measure_level(const character::Model& cally, std::size_t walk, int level, const Options& o) {
  const Clock::time_point level_start = Clock::now();
  SINEW_ASSIGN_OR_RETURN(const character::Model model, editor::subdivide(cally, level));
  Table2Row row;
  row.level = level;
  row.triangles = model.mesh.triangle_count();
  const int bake_threads = *std::max_element(o.threads.begin(), o.threads.end());
  std::fprintf(stderr, "paper: table 2 level %d (%zu triangles): baking on %d thread%s...\n", level, row.triangles,
               bake_threads, bake_threads == 1 ? "" : "s");
  character::InMemoryBake bake;
  {
    JobSystem jobs(bake_threads);
    character::BakeRequest request;
    request.pose_space = table2_pose_space(o);
    SINEW_ASSIGN_OR_RETURN(bake, character::bake_in_memory(model, request, jobs));
  }
  const rt::FuzzyBakeStats& b = bake.fuzzy.stats;
  row.samples = b.sample_count;
  row.pose_sampling_ms = bake.pose_sampling_ms;
  row.fuzzy_sampling_ms = b.sampling_ms;
  row.assignment_ms = b.assignment_ms;
  row.build_ms = b.build_ms;
  row.sampling_s = (bake.pose_sampling_ms + b.sampling_ms + b.assignment_ms) / 1000.0;
  row.build_s = b.build_ms / 1000.0;
  row.tris_per_leaf = b.mean_items_per_leaf;
  std::fprintf(stderr, "paper:   baked (sampling %.2f s, build %.2f s); brute-force check...\n", row.sampling_s,
               row.build_s);

  BenchStage stage;
  SINEW_RETURN_IF_ERROR(stage_instances(model, bake.fuzzy.view(), 1, stage));
  const anim::Clip& clip = model.clips[walk];
  const double duration = clip.duration();
  const PoseFrame pose = [&](int f, BenchStage& s) {
    return pose_instances(model, clip, duration * f / o.frames, s);
  };
  SINEW_ASSIGN_OR_RETURN(const FirstFrame first,
                         frame_and_gate(stage, pose, o.width, o.height, o.check_stride, bake_threads));
  row.gate = first.gate;
  if (!first.gate.result.passed()) {
    row.failed = true;
    return row;
  }
  for (int threads : o.threads) {
    std::fprintf(stderr, "paper:   rendering %d frames on %d thread%s...\n", o.frames, threads,
                 threads == 1 ? "" : "s");
    SINEW_ASSIGN_OR_RETURN(const FpsPair fps, measure_fps(stage, first, pose, o.frames, threads));
    row.fps.emplace_back(threads, fps);
  }
  std::fprintf(stderr, "paper:   level %d done in %.1f s\n", level, ms_since(level_start) / 1000.0);
  return row;
}

// y at x on the line through (x0, y0) and (x1, y1) in log-log space (the
// paper's columns grow as powers of the triangle count).
double interpolate_loglog(double x, double x0, double y0, double x1, double y1) {
  if (!(y0 > 0.0 && y1 > 0.0)) return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
  const double f = (std::log(x) - std::log(x0)) / (std::log(x1) - std::log(x0));
  return std::exp(std::log(y0) + f * (std::log(y1) - std::log(y0)));
}

// Rows at the paper's counts that no level hits, between the measured
// (unfailed) levels that bracket them.
std::vector<Table2Row> interpolated_rows(const std::vector<Table2Row>& measured) {
  std::vector<Table2Row> out;
  for (const PaperTable2Row& paper : kPaperTable2Cally) {
    const double x = paper.triangles;
    for (std::size_t i = 0; i + 1 < measured.size(); ++i) {
      const Table2Row& a = measured[i];
      const Table2Row& b = measured[i + 1];
      if (a.failed || b.failed) continue;
      const double xa = static_cast<double>(a.triangles), xb = static_cast<double>(b.triangles);
      if (!(xa < x && x < xb)) continue;
      // A level within 15% of the paper's count is its row already.
      if (std::fabs(xa - x) < 0.15 * x || std::fabs(xb - x) < 0.15 * x) break;
      Table2Row r;
      r.level = -1;
      r.triangles = static_cast<std::size_t>(paper.triangles);
      r.interpolated = true;
      const auto at = [&](double ya, double yb) { return interpolate_loglog(x, xa, ya, xb, yb); };
      r.sampling_s = at(a.sampling_s, b.sampling_s);
      r.build_s = at(a.build_s, b.build_s);
      r.tris_per_leaf = at(a.tris_per_leaf, b.tris_per_leaf);
      for (std::size_t k = 0; k < a.fps.size() && k < b.fps.size(); ++k) {
        FpsPair f;
        f.primary = at(a.fps[k].second.primary, b.fps[k].second.primary);
        f.primary_shadows = at(a.fps[k].second.primary_shadows, b.fps[k].second.primary_shadows);
        r.fps.emplace_back(a.fps[k].first, f);
      }
      out.push_back(std::move(r));
      break;
    }
  }
  return out;
}

// The paper row a Sinew row stands beside: the paper's count within 15%.
const PaperTable2Row* paper_row_for(std::size_t triangles) {
  for (const PaperTable2Row& p : kPaperTable2Cally) {
    if (std::fabs(static_cast<double>(triangles) - p.triangles) < 0.15 * p.triangles) return &p;
  }
  return nullptr;
}

std::string gate_text(const GateReport& g) {
  if (!g.result.passed()) {
    return "FAILED brute-force check (" + std::to_string(g.result.mismatched) + " of " +
           std::to_string(g.result.checked) + " sampled pixels differ)";
  }
  std::string text = std::to_string(g.result.checked) + " px ok";
  if (g.result.grazes) text += ", " + std::to_string(g.result.grazes) + " grazes";
  return text;
}

// A table's two header lines: `left` columns (with their `rule`), two fps
// columns per thread count, then the brute-force column and four paper
// columns (`right`).
std::string table_head(const std::string& left, const std::string& rule_left, const std::vector<int>& threads,
                       const std::string& right) {
  std::string head = left, rule = rule_left;
  for (int t : threads) {
    head += " fps " + std::to_string(t) + "T primary | fps " + std::to_string(t) + "T +shadows |";
    rule += "---:|---:|";
  }
  return head + right + "\n" + rule + "---|---:|---:|---:|---:|\n";
}

// The Markdown table (printed and written): Sinew's rows by triangle count,
// the paper's row beside those at its counts.
std::string table2_markdown(const std::vector<Table2Row>& rows, const std::vector<int>& threads) {
  std::string md = table_head("| level | triangles | sampling s | build s | tris/leaf |", "|---|---:|---:|---:|---:|",
                              threads,
                              " brute force | paper tris | paper sampling s | paper build s | paper fps (1 core) |");
  for (const Table2Row& r : rows) {
    md += "| " + (r.interpolated ? std::string("interpolated") : std::to_string(r.level)) + " | " +
          std::to_string(r.triangles) + " | ";
    if (r.failed) {
      md += gate_text(r.gate) + " | | |";
      for (std::size_t k = 0; k < threads.size(); ++k) md += " | |";
      md += " FAILED |";
    } else {
      md += fixed(r.sampling_s, 2) + " | " + fixed(r.build_s, 2) + " | " + fixed(r.tris_per_leaf, 2) + " |";
      for (int t : threads) {
        const auto it = std::find_if(r.fps.begin(), r.fps.end(), [&](const auto& p) { return p.first == t; });
        if (it == r.fps.end()) {
          md += " - | - |";
        } else {
          md += " " + fixed(it->second.primary, 2) + " | " + fixed(it->second.primary_shadows, 2) + " |";
        }
      }
      md += " " + (r.interpolated ? std::string("(log-log between levels)") : gate_text(r.gate)) + " |";
    }
    if (const PaperTable2Row* p = paper_row_for(r.triangles)) {
      md += " " + std::to_string(p->triangles / 1000) + "k | " + fixed(p->sampling_s, 2) + " | " +
            fixed(p->build_s, 2) + " | " + fixed(p->fps, 1) + " |\n";
    } else {
      md += " | | | |\n";
    }
  }
  return md;
}

Json fps_json(const FpsByThreads& fps) {
  Json out = Json::object();
  for (const auto& [threads, f] : fps) {
    out[std::to_string(threads)] = {{"primary", f.primary},
                                    {"primary_shadows", f.primary_shadows},
                                    {"triangle_tests_per_primary_ray", f.triangle_tests_per_ray},
                                    {"node_visits_per_primary_ray", f.node_visits_per_ray}};
  }
  return out;
}

Json gate_json(const GateReport& g) {
  return {{"passed", g.result.passed()},    {"stride", g.stride},
          {"checked", g.result.checked},    {"mismatched", g.result.mismatched},
          {"edge_grazes", g.result.grazes}, {"reference_ms", g.reference_ms}};
}

Json table2_row_json(const Table2Row& r) {
  Json row = {{"level", r.interpolated ? Json(nullptr) : Json(r.level)},
              {"triangles", r.triangles},
              {"interpolated", r.interpolated}};
  if (!r.interpolated) row["brute_force"] = gate_json(r.gate);
  if (r.failed) {
    row["failed"] = true;
    return row;
  }
  row["sampling_s"] = r.sampling_s;
  row["build_s"] = r.build_s;
  if (!r.interpolated) {
    row["samples"] = r.samples;
    row["pose_sampling_ms"] = r.pose_sampling_ms;
    row["fuzzy_sampling_ms"] = r.fuzzy_sampling_ms;
    row["assignment_ms"] = r.assignment_ms;
    row["build_ms"] = r.build_ms;
  }
  row["tris_per_leaf"] = r.tris_per_leaf;
  row["fps"] = fps_json(r.fps);
  return row;
}

// --- Table 1 ------------------------------------------------------------------------

struct Table1Row {
  std::string mode;
  int requested = 0;
  std::uint32_t samples = 0;  // poses actually sampled
  bool failed = false;
  GateReport gate;
  double fuzzy_area = 0.0;
  double rest_area = 0.0;
  double tris_per_leaf = 0.0;
  std::size_t escaped_triangles = 0;  // of the rest pose, routed through the fallback
  FpsByThreads fps;
};

// How many clip poses a limit set rejects (is_within, 1e-3 rad: the
// mannequin test's tolerance) at the clips' key times, and at key times +
// 30 Hz.
struct LimitsCheck {
  std::size_t key_poses = 0;
  std::size_t key_violations = 0;  // (pose, joint) pairs outside
  std::size_t frame_poses = 0;
  std::size_t frame_violations = 0;
  std::vector<std::string> worst;  // joints that violate, with their count at the key times
};

constexpr float kLimitsTolerance = 1e-3f;

Expected<std::pair<std::size_t, std::size_t>> count_violations(const character::Model& model,
                                                               const anim::JointLimits& limits, bool every_frame,
                                                               std::vector<std::size_t>* per_joint) {
  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kClips;
  space.samples = 0;
  space.every_frame_30hz = every_frame;
  const anim::Skeleton& sk = model.skeleton;
  std::size_t poses = 0, violations = 0;
  SINEW_RETURN_IF_ERROR(anim::for_each_pose(
      space, sk, model.clips, {}, [&](std::span<const anim::JointTransform> local) -> Status {
        ++poses;
        for (std::size_t j = 0; j < local.size(); ++j) {
          const Quat delta = glm::inverse(sk.rest_pose()[j].rotation) * local[j].rotation;
          if (anim::is_within(limits[j], delta, kLimitsTolerance)) continue;
          ++violations;
          if (per_joint) ++(*per_joint)[j];
        }
        return {};
      }));
  return std::pair{poses, violations};
}

Expected<LimitsCheck> check_limits(const character::Model& model, const anim::JointLimits& limits) {
  LimitsCheck check;
  std::vector<std::size_t> per_joint(model.skeleton.joint_count(), 0);
  SINEW_ASSIGN_OR_RETURN(const auto keys, count_violations(model, limits, false, &per_joint));
  SINEW_ASSIGN_OR_RETURN(const auto frames, count_violations(model, limits, true, nullptr));
  check.key_poses = keys.first;
  check.key_violations = keys.second;
  check.frame_poses = frames.first;
  check.frame_violations = frames.second;
  for (std::size_t j = 0; j < per_joint.size(); ++j) {
    if (per_joint[j]) check.worst.push_back(model.skeleton.names()[j] + " " + std::to_string(per_joint[j]));
  }
  return check;
}

// Per joint, the XYZ Euler angles (degrees) of its rotation relative to rest
// over every clip key pose: the data Cally's limits were written from.
Status print_clip_ranges(const character::Model& model) {
  const anim::Skeleton& sk = model.skeleton;
  const std::size_t n = sk.joint_count();
  std::vector<Vec3> lo(n, Vec3(1e9f)), hi(n, Vec3(-1e9f));
  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kClips;
  space.samples = 0;
  space.every_frame_30hz = true;
  SINEW_RETURN_IF_ERROR(anim::for_each_pose(space, sk, model.clips, {},
                                            [&](std::span<const anim::JointTransform> local) -> Status {
                                              for (std::size_t j = 0; j < n; ++j) {
                                                const Quat delta =
                                                    glm::inverse(sk.rest_pose()[j].rotation) * local[j].rotation;
                                                const Vec3 a = anim::decompose_euler(anim::RotationOrder::kXYZ,
                                                                                     delta).angles;
                                                lo[j] = glm::min(lo[j], a);
                                                hi[j] = glm::max(hi[j], a);
                                              }
                                              return {};
                                            }));
  const auto deg = [](float radians) { return static_cast<double>(radians) * 57.29577951308232; };
  std::printf("joint (parent): XYZ Euler degrees relative to rest, min .. max over clip poses (keys + 30 Hz)\n");
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = sk.parents()[j];
    std::printf("  %-24s (%s): x %7.1f .. %7.1f  y %7.1f .. %7.1f  z %7.1f .. %7.1f\n", sk.names()[j].c_str(),
                parent < 0 ? "-" : sk.names()[static_cast<std::size_t>(parent)].c_str(), deg(lo[j].x),
                deg(hi[j].x), deg(lo[j].y), deg(hi[j].y), deg(lo[j].z), deg(hi[j].z));
  }
  return {};
}

anim::PoseSpaceDesc table1_pose_space(const PaperTable1Row& paper, const std::string& walk) {
  anim::PoseSpaceDesc space;
  space.mode = *anim::parse_pose_space_mode(paper.mode);
  space.samples = paper.samples;
  if (space.mode == anim::PoseSpaceMode::kClips || space.mode == anim::PoseSpaceMode::kClip) {
    space.every_frame_30hz = true;  // so enough times exist for the paper's counts
  }
  if (space.mode == anim::PoseSpaceMode::kClip) space.clips = {walk};
  return space;
}

Expected<Table1Row> measure_mode(const character::Model& model, const std::string& name,
                                 const PaperTable1Row& paper, const anim::JointLimits& limits,
                                 const std::string& walk, const Options& o) {
  Table1Row row;
  row.mode = paper.mode;
  row.requested = paper.samples;
  const int bake_threads = *std::max_element(o.threads.begin(), o.threads.end());
  std::fprintf(stderr, "paper: table 1 %s, pose space %s (%d samples): baking...\n", name.c_str(), paper.mode,
               paper.samples);
  character::InMemoryBake bake;
  {
    JobSystem jobs(bake_threads);
    character::BakeRequest request;
    request.pose_space = table1_pose_space(paper, walk);
    if (request.pose_space.mode == anim::PoseSpaceMode::kLimits) request.limits = limits;
    SINEW_ASSIGN_OR_RETURN(bake, character::bake_in_memory(model, request, jobs));
  }
  const rt::FuzzyBakeStats& b = bake.fuzzy.stats;
  row.samples = b.sample_count;
  row.fuzzy_area = b.fuzzy_area;
  row.rest_area = b.rest_area;
  row.tris_per_leaf = b.mean_items_per_leaf;

  BenchStage stage;
  SINEW_RETURN_IF_ERROR(stage_instances(model, bake.fuzzy.view(), 1, stage));
  SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> rest, character::rest_skinning(model, stage.placements[0]));
  const PoseFrame pose = [&](int, BenchStage& s) { return s.scene.set_bones(s.ids[0], rest); };
  SINEW_ASSIGN_OR_RETURN(const FirstFrame first,
                         frame_and_gate(stage, pose, o.width, o.height, o.check_stride, bake_threads));
  row.gate = first.gate;
  if (!first.gate.result.passed()) {
    row.failed = true;
    return row;
  }
  {
    JobSystem jobs(1);
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats stats, stage.scene.prepare_frame(rt::FrameOptions{}, jobs));
    row.escaped_triangles = stats.escaped_triangles;
  }
  for (int threads : o.threads) {
    SINEW_ASSIGN_OR_RETURN(const FpsPair fps, measure_fps(stage, first, pose, o.frames, threads));
    row.fps.emplace_back(threads, fps);
  }
  return row;
}

struct Table1Model {
  std::string name;
  std::size_t triangles = 0;
  std::string limits_source;
  std::optional<LimitsCheck> limits_check;
  std::vector<Table1Row> rows;
};

std::string table1_markdown(const Table1Model& m, const std::vector<int>& threads) {
  std::string md = table_head(
      "| pose space | samples | fuzzy area | / rest area | tris/leaf | escaped tris | tri tests/ray |",
      "|---|---:|---:|---:|---:|---:|---:|", threads,
      " brute force | paper samples | paper fuzzy area | paper tris/leaf | paper fps |");
  for (const Table1Row& r : m.rows) {
    const PaperTable1Row* paper = nullptr;
    for (const PaperTable1Row& p : kPaperTable1) {
      if (r.mode == p.mode) paper = &p;
    }
    md += "| " + r.mode + " | " + std::to_string(r.samples) + " |";
    if (r.failed) {
      md += " " + gate_text(r.gate) + " | | | | |";
      for (std::size_t k = 0; k < threads.size(); ++k) md += " | |";
      md += " FAILED |";
    } else {
      md += " " + general(r.fuzzy_area, 4) + " | " + fixed(r.rest_area > 0.0 ? r.fuzzy_area / r.rest_area : 0.0, 2) +
            " | " + fixed(r.tris_per_leaf, 2) + " | " + std::to_string(r.escaped_triangles) + " | " +
            fixed(r.fps.empty() ? 0.0 : r.fps.front().second.triangle_tests_per_ray, 1) + " |";
      for (const auto& [t, f] : r.fps) md += " " + fixed(f.primary, 2) + " | " + fixed(f.primary_shadows, 2) + " |";
      md += " " + gate_text(r.gate) + " |";
    }
    if (paper) {
      md += " " + std::to_string(paper->samples) + " | " + fixed(paper->fuzzy_area / 1000.0, 0) + "k" + " | " +
            fixed(paper->tris_per_leaf, 1) + " | " + fixed(paper->fps, 1) + " |\n";
    } else {
      md += " | | | |\n";
    }
  }
  return md;
}

Json table1_json(const Table1Model& m) {
  Json model = {{"model", m.name}, {"triangles", m.triangles}, {"limits", m.limits_source}};
  if (m.limits_check) {
    const LimitsCheck& c = *m.limits_check;
    model["limits_check"] = {{"tolerance_rad", kLimitsTolerance}, {"key_poses", c.key_poses},
                             {"key_violations", c.key_violations}, {"poses_30hz", c.frame_poses},
                             {"violations_30hz", c.frame_violations}, {"violating_joints", c.worst}};
  }
  model["rows"] = Json::array();
  for (const Table1Row& r : m.rows) {
    Json row = {{"mode", r.mode}, {"requested_samples", r.requested}, {"samples", r.samples},
                {"brute_force", gate_json(r.gate)}};
    if (r.failed) {
      row["failed"] = true;
    } else {
      row["fuzzy_area"] = r.fuzzy_area;
      row["rest_area"] = r.rest_area;
      row["area_ratio"] = r.rest_area > 0.0 ? r.fuzzy_area / r.rest_area : 0.0;
      row["tris_per_leaf"] = r.tris_per_leaf;
      row["escaped_triangles"] = r.escaped_triangles;
      row["fps"] = fps_json(r.fps);
    }
    model["rows"].push_back(std::move(row));
  }
  return model;
}

// --- the run --------------------------------------------------------------------------

struct Run {
  const Options* o = nullptr;
  std::string command_line;
  BenchRecord* record = nullptr;
  std::string markdown;

  void fail(const std::string& what, const Status& s) { record->fail(what, s); }
  Json& doc() { return record->doc(); }
};

std::string method_threads(const Options& o) {
  return join_ints(o.threads) + " render thread" + (o.threads.size() == 1 && o.threads[0] == 1 ? "" : "s");
}

void run_table2(const character::Model& cally, Run& run) {
  const Options& o = *run.o;
  const auto walk = find_walk_clip(cally, "cally");
  if (!walk.ok()) return run.fail("table 2", walk.status());
  std::vector<Table2Row> measured;
  for (int level : o.levels) {
    auto row = measure_level(cally, *walk, level, o);
    if (!row.ok()) {
      run.fail("table 2 level " + std::to_string(level), row.status());
      continue;
    }
    if (row->failed) run.record->mark_failed();
    measured.push_back(std::move(*row));
  }
  std::vector<Table2Row> rows = measured;
  for (Table2Row& r : interpolated_rows(measured)) rows.push_back(std::move(r));
  std::vector<int> unmatched;  // paper rows no measured or interpolated row stands beside
  for (const PaperTable2Row& p : kPaperTable2Cally) {
    const bool matched = std::any_of(rows.begin(), rows.end(), [&](const Table2Row& r) {
      return !r.failed && paper_row_for(r.triangles) == &p;
    });
    if (!matched) unmatched.push_back(p.triangles);
  }
  std::stable_sort(rows.begin(), rows.end(), [](const Table2Row& a, const Table2Row& b) {
    return a.triangles < b.triangles;
  });

  const int bake_threads = *std::max_element(o.threads.begin(), o.threads.end());
  const std::string pose_space =
      o.samples > 0 ? "all clips, key times + 30 Hz, at most " + std::to_string(o.samples) + " poses"
                    : "all clips, key times + 30 Hz (character::default_pose_space)";
  std::string md = "## Paper Table 2: performance vs mesh size (Cally, subdivided)\n\n";
  md += "Method: Cally (Cal3D, " + std::to_string(cally.mesh.triangle_count()) +
        " triangles) subdivided by editor::subdivide at levels " + join_ints(o.levels) +
        " (each level splits every triangle into four). Each level is baked in memory over the pose space " +
        pose_space + " on " + std::to_string(bake_threads) + " thread" + (bake_threads == 1 ? "" : "s") +
        "; *sampling* = pose sampling + fuzzy box sampling + bone assignment, *build* = the per-bone fuzzy trees "
        "(the paper's two preprocessing columns; " +
        std::string(rt::FuzzyBakeOptions{}.bone_trees == rt::BoneTreeKind::kBvh
                        ? "BVHs, Sinew's default, where the paper builds kd-trees: docs/RAYTRACE.md \"Bone trees: kd-tree or BVH\""
                        : "kd-trees, as the paper's") +
        "). One character on the ground plane is rendered at " +
        std::to_string(o.width) + "x" + std::to_string(o.height) +
        " with diffuse shading and a point light on " + method_threads(o) + ", at " + std::to_string(o.frames) +
        " times evenly spread over the walk clip; a frame is set_bones + prepare_frame + render, fps = 1000 / median "
        "frame ms, *primary* without shadow rays (as in the paper), *+shadows* with one shadow ray per lit hit. "
        "Each level's first frame is checked against brute force on every " +
        std::to_string(o.check_stride) +
        "th pixel before it is timed (a level that fails shows FAILED and no numbers). Rows marked *interpolated* sit at the paper's triangle counts, log-log between "
        "the neighbouring measured levels. The paper's numbers are for one 2.4 GHz Opteron core (2006) and 4x4 SSE "
        "packets. Command: `" + run.command_line + "`.\n\n";
  md += table2_markdown(rows, o.threads);
  if (!unmatched.empty()) {
    md += "\nNo Sinew row (outside the measured levels, or beside a failed one) for the paper's rows at " +
          join_ints(unmatched) + " triangles.\n";
  }
  std::printf("\n%s", md.c_str());
  std::fflush(stdout);
  run.markdown += md + "\n";

  Json table = {{"model", "cally"},
                {"bake_threads", bake_threads},
                {"pose_space", pose_space},
                {"size", {o.width, o.height}},
                {"frames", o.frames},
                {"check_stride", o.check_stride},
                {"rows", Json::array()},
                {"paper", Json::array()}};
  for (const Table2Row& r : rows) table["rows"].push_back(table2_row_json(r));
  for (const PaperTable2Row& p : kPaperTable2Cally) {
    table["paper"].push_back(
        {{"triangles", p.triangles}, {"sampling_s", p.sampling_s}, {"build_s", p.build_s}, {"fps", p.fps}});
  }
  run.doc()["table2"] = std::move(table);
}

Expected<anim::JointLimits> limits_for(const std::string& name, const character::Model& model,
                                       const Options& o, std::string& source) {
  if (name == "mannequin") {
    source = "content::mannequin_joint_limits";
    return content::mannequin_joint_limits(model.skeleton);
  }
  source = o.cally_limits == default_cally_limits() ? "content/limits/cally.json" : o.cally_limits;
  return anim::load_joint_limits(o.cally_limits, model.skeleton);
}

void run_table1(std::optional<character::Model>& cally, Run& run) {
  const Options& o = *run.o;
  std::string md = "## Paper Table 1: pose space vs fuzzy area and rest-pose fps\n\n";
  md += "Method: for each model, four in-memory bakes with the paper's pose spaces and sample counts: arbitrary "
        "(1000 uniform random joint rotations), limits (245 rotations uniform inside the joint limits; the mannequin's "
        "content::mannequin_joint_limits, Cally's content/limits/cally.json), clips (at most 124 poses from all clips' "
        "key times + 30 Hz) and clip (at most 62 from the walk alone); *samples* is how many poses were sampled. "
        "*Fuzzy area* is the sum of the triangles' fuzzy box areas (model units), beside its ratio to the rest-pose "
        "boxes' area; *tris/leaf* the mean over the bone trees' non-empty leaves; *escaped tris* the rest-pose "
        "triangles outside their fuzzy boxes (traced through the per-frame fallback tree). The rest pose is rendered "
        "from one viewpoint per model (framed on it) at " +
        std::to_string(o.width) + "x" + std::to_string(o.height) + ", diffuse shading, point light, on " +
        method_threads(o) + "; a frame is set_bones + prepare_frame + render, fps = 1000 / median of " +
        std::to_string(o.frames) + " frames; *tri tests/ray* counts triangle tests per primary ray (1 thread), the work "
        "the fuzzy area predicts, free of timing noise. Each mode's first frame is checked against brute force on "
        "every " + std::to_string(o.check_stride) + "th pixel (a failure shows FAILED and no numbers). The paper's rows are its UT 2003 model (another mesh and scale: compare trends and ratios, not "
        "absolute areas). Command: `" + run.command_line + "`.\n\n";
  Json models = Json::array();
  std::string walk_name = "walk";
  for (const std::string name : {"cally", "mannequin"}) {
    std::optional<character::Model> loaded;
    if (name == "cally") {
      if (!cally) continue;
      loaded = *cally;
    } else {
      std::string note;
      auto m = load_model(name, run.o->shared, note);
      if (!m.ok()) {
        run.fail(name, m.status());
        continue;
      }
      loaded = std::move(**m);
    }
    const character::Model& model = *loaded;
    Table1Model result;
    result.name = name;
    result.triangles = model.mesh.triangle_count();
    auto limits = limits_for(name, model, o, result.limits_source);
    if (!limits.ok()) {
      run.fail(name + " joint limits", limits.status());
      continue;
    }
    auto check = check_limits(model, *limits);
    if (!check.ok()) {
      run.fail(name + " joint limits check", check.status());
    } else {
      result.limits_check = *check;
    }
    for (const PaperTable1Row& paper : kPaperTable1) {
      auto row = measure_mode(model, name, paper, *limits, walk_name, o);
      if (!row.ok()) {
        run.fail(name + " " + paper.mode, row.status());
        continue;
      }
      if (row->failed) run.record->mark_failed();
      result.rows.push_back(std::move(*row));
    }
    md += "### " + name + " (" + std::to_string(result.triangles) + " triangles)\n\n";
    if (result.limits_check) {
      const LimitsCheck& c = *result.limits_check;
      md += "Joint limits (" + result.limits_source + "): " + std::to_string(c.key_violations) +
            " (pose, joint) violations over " + std::to_string(c.key_poses) + " clip key poses, " +
            std::to_string(c.frame_violations) + " over " + std::to_string(c.frame_poses) +
            " key + 30 Hz poses (anim::is_within, tolerance 1e-3 rad)";
      if (!c.worst.empty()) {
        md += "; violating joints:";
        for (const std::string& w : c.worst) md += " " + w;
      }
      md += ".\n\n";
    }
    md += table1_markdown(result, o.threads) + "\n";
    models.push_back(table1_json(result));
  }
  std::printf("\n%s", md.c_str());
  std::fflush(stdout);
  run.markdown += md;
  run.doc()["table1"] = std::move(models);
  Json paper = Json::array();
  for (const PaperTable1Row& p : kPaperTable1) {
    paper.push_back({{"model", "ut2003"},
                     {"mode", p.mode},
                     {"samples", p.samples},
                     {"fuzzy_area", p.fuzzy_area},
                     {"tris_per_leaf", p.tris_per_leaf},
                     {"fps", p.fps}});
  }
  run.doc()["paper_table1"] = std::move(paper);
}

bool wants(const Options& o, int table) {
  return std::find(o.tables.begin(), o.tables.end(), table) != o.tables.end();
}

}  // namespace

int run_paper_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("paper", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;

  std::string note;
  auto loaded = load_model("cally", o.shared, note);
  if (!loaded.ok()) {
    std::fprintf(stderr, "sinew-bench paper: cally: %s\n", loaded.status().message().c_str());
    return 1;
  }
  std::optional<character::Model> cally = std::move(*loaded);
  if (o.clip_ranges) {
    if (!cally) {
      std::fprintf(stderr, "sinew-bench paper: %s\n", note.c_str());
      return 1;
    }
    const Status s = print_clip_ranges(*cally);
    if (!s.ok()) std::fprintf(stderr, "sinew-bench paper: %s\n", s.message().c_str());
    return s.ok() ? 0 : 1;
  }

  const Clock::time_point start = Clock::now();
  BenchRecord record("paper", command_line, o.threads);
  std::printf("  Günther et al. 2006, Tables 1 and 2; %dx%d, %d frames per configuration, brute-force check of\n"
              "  every %dth pixel of each configuration's first frame\n",
              o.width, o.height, o.frames, o.check_stride);
  std::fflush(stdout);

  Run run;
  run.o = &o;
  run.command_line = command_line;
  run.record = &record;
  if (!cally) {
    // Table 2 is Cally's; Table 1 still measures the mannequin.
    record.note(note);
    record.mark_failed();
  }
  if (wants(o, 2) && cally) run_table2(*cally, run);
  if (wants(o, 1)) run_table1(cally, run);

  const double wall_s = ms_since(start) / 1000.0;
  const std::string load_end = load_average();
  std::printf("\n  wall time %.1f s; load at the end: %s (1, 5, 15 min)\n", wall_s, load_end.c_str());
  run.doc()["wall_s"] = wall_s;
  run.doc()["load_average_end"] = load_end;
  return record.finish(o.json_path, o.markdown_path, run.markdown);
}

}  // namespace sinew::bench
