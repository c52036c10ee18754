#include "editor/cli/pack_commands.h"
#include "editor/cli/shown_text.h"

#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "animation/joint_limits.h"
#include "character/bake.h"
#include "character/pack.h"
#include "editor/cli/import_limit_flags.h"
#include "editor/cli/scene_savings.h"
#include "editor/import/model_loader.h"
#include "editor/mesh/subdivide.h"
#include "editor/scene/scene_recipe.h"
#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "runtime/io/mapped_file.h"
#include "runtime/jobs/job_system.h"
#include "runtime/pack/checksum.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::editor {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

// "17 of 37 bones merged into their parents' trees" / "rigid bones kept".
std::string rigid_bones_text(const rt::FuzzyBakeStats& st) {
  if (!st.merge_rigid_bones) return "rigid bones kept";
  return std::to_string(st.merged_bones) + " of " + std::to_string(st.bone_count) +
         " bones merged into their parents' trees";
}

// --- bake options ---------------------------------------------------------------

struct BakeOptions {
  std::string model_path;  // may come from the scene recipe
  std::optional<SceneRecipe> scene;
  std::string out_path;
  anim::PoseSpaceDesc pose_space = character::default_pose_space();
  std::string limits_path;
  float padding = 0.0f;
  rt::CandidateBones candidates = rt::CandidateBones::kAll;
  bool merge_rigid_bones = rt::FuzzyBakeOptions{}.merge_rigid_bones;
  float sah_intersection_cost = rt::FuzzyBakeOptions{}.kd.intersection_cost;
  bool sah_intersection_cost_given = false;  // else the bake's size-based default
  std::optional<std::uint32_t> pose_clusters;  // else the bake's size-based default
  rt::BoneTreeKind bone_trees = rt::FuzzyBakeOptions{}.bone_trees;
  int bvh_leaf = rt::BvhBuildOptions{}.max_leaf_items;
  int threads = 0;
  std::size_t max_memory_bytes = character::BakeRequest{}.max_memory_bytes;
  GltfImportOptions gltf;
  // --scene: what the scene saved against the whole model (scene_savings.h).
  enum class SceneReport { kFull, kSizes, kOff } scene_report = SceneReport::kFull;
  SceneSavingsOptions scene_report_run;
  bool help = false;
};

// bake's options, declared in the order --help lists them.
struct BakeFlags {
  explicit BakeFlags(cli::CommandLine& l)
      : model(l.positionals("MODEL", ".gltf, .glb, .cfg (Cal3D) or a model-only .pack", 1)),
        asset_roots(l.option("--asset-roots", "A:B",
                             "more folders a glTF file's buffers may be read from (by\n"
                             "default only its own folder and below)")),
        scene(l.option("--scene", "RECIPE.json",
                       "bake only what a scene needs: the pose space of the recipe's\n"
                       "clips, and only those clips in the pack (content/scenes/)")),
        scene_report(l.option("--scene-report", "full|sizes|off",
                              "with --scene, what it saved against the whole model (every\n"
                              "clip, every bone its own tree): bones, pack bytes and\n"
                              "(full, the default) fps rendering both side by side")),
        scene_report_frames(l.option("--scene-report-frames", "N", "frames rendered per pack (default 30)")),
        scene_report_size(l.option("--scene-report-size", "WxH", "their size (default 1024x1024)")),
        out(l.option("-o,--out", "OUT.pack",
                     "the pack to write (atomically: an existing file is replaced\n"
                     "only by a complete new pack)")),
        pose_space(l.option("--pose-space", "MODE",
                            "arbitrary | limits | clips | clip:NAME (default clips: every\n"
                            "key of every clip, and every 1/30 s)")),
        clips(l.option("--clips", "a,b,c", "the clips of --pose-space clips (default all)")),
        samples(l.option("--samples", "N",
                         "poses: arbitrary/limits need N > 0 (default 1000); clip modes:\n"
                         "at most N of the key times (0 = all)")),
        seed(l.option("--seed", "S", "random pose seed (default 1)")),
        limits(l.option("--limits", "FILE.json", "joint limits (needed by --pose-space limits; stored in the pack)")),
        pad(l.option("--pad", "FRACTION", "grow every fuzzy box by this fraction of the model's size (default 0)")),
        candidates(l.option("--candidates", "MODE", "all (the paper's) | influencing (faster; default all)")),
        rigid_bones(l.option("--rigid-bones", "merge|keep",
                             "a bone that never moves relative to its parent in the pose\n"
                             "space gives its triangles to the parent's tree (merge: fewer\n"
                             "top-level objects per frame; default) or keeps its own (keep)")),
        sah_intersection_cost(l.option("--sah-intersection-cost", "C",
                                       "the bone trees' triangle cost against a cell visit's 1\n"
                                       "(default 0.15, 0.05 from 25,000 triangles, tuned for\n"
                                       "256-ray packets; 1.5 builds deeper trees, which suit\n"
                                       "--packet-rays 1)")),
        pose_clusters(l.option("--pose-clusters", "K",
                               "per bone up to K clusters of its poses, each with a tighter\n"
                               "tree the bone uses in the poses nearest it (0-64; default 16\n"
                               "from 25,000 triangles, else 0: none; docs/RAYTRACE.md,\n"
                               "\"Pose-space clusters\")")),
        bone_trees(l.option("--bone-trees", "kd|bvh",
                            "the bone trees' structure: the paper's kd-trees, or BVHs\n"
                            "listing each triangle once (docs/RAYTRACE.md, \"Bone trees:\n"
                            "kd-tree or BVH\"; default bvh)")),
        bvh_leaf(l.option("--bvh-leaf", "N", "with --bone-trees bvh: at most N triangles a leaf (default 32)")),
        threads(l.option("--threads", "N", "worker threads (default 0: all cores)")),
        max_memory_mib(l.option("--max-memory-mib", "M",
                                "refuse a bake whose working set would exceed M MiB\n"
                                "(default 8192, at least 4; a quarter of it at most goes\n"
                                "to the fuzzy boxes, processed in bone chunks)")),
        import_limits(l) {}

  const std::vector<std::string>& model;
  const std::optional<std::string>& asset_roots;
  const std::optional<std::string>& scene;
  const std::optional<std::string>& scene_report;
  const std::optional<std::string>& scene_report_frames;
  const std::optional<std::string>& scene_report_size;
  const std::optional<std::string>& out;
  const std::optional<std::string>& pose_space;
  const std::optional<std::string>& clips;
  const std::optional<std::string>& samples;
  const std::optional<std::string>& seed;
  const std::optional<std::string>& limits;
  const std::optional<std::string>& pad;
  const std::optional<std::string>& candidates;
  const std::optional<std::string>& rigid_bones;
  const std::optional<std::string>& sah_intersection_cost;
  const std::optional<std::string>& pose_clusters;
  const std::optional<std::string>& bone_trees;
  const std::optional<std::string>& bvh_leaf;
  const std::optional<std::string>& threads;
  const std::optional<std::string>& max_memory_mib;
  ImportLimitFlags import_limits;
};

std::unique_ptr<cli::CommandLine> bake_command_line() {
  auto line = std::make_unique<cli::CommandLine>(
      "sinew-editor bake",
      "Bakes a model's fuzzy kd-trees into a content pack:\n"
      "  sinew-editor bake MODEL -o OUT.pack [options]\n"
      "  sinew-editor bake --scene RECIPE.json [MODEL] -o OUT.pack [options]\n");
  line->footer("Set SOURCE_DATE_EPOCH for a reproducible pack (fixed date, no timings).\n");
  return line;
}

Expected<BakeOptions> parse_bake_options(const std::vector<std::string>& args, cli::CommandLine& line,
                                         const BakeFlags& f) {
  SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, line.parse(args));
  BakeOptions o;
  if (result == cli::ParseResult::kHelp) {
    o.help = true;
    return o;
  }
  if (const std::optional<std::string>& v = f.scene) {
    if (f.pose_space || f.clips) {
      return invalid_argument("--scene", *v, "the recipe sets the pose space: drop --pose-space and --clips");
    }
    SINEW_ASSIGN_OR_RETURN(SceneRecipe recipe, load_scene_recipe(*v));
    o.model_path = recipe.model_path;
    o.pose_space.mode = anim::PoseSpaceMode::kClips;
    o.pose_space.clips = recipe.clips;
    o.pose_space.samples = recipe.samples;
    o.pose_space.every_frame_30hz = recipe.every_frame_30hz;
    o.padding = recipe.padding;
    o.scene = std::move(recipe);
  }
  if ((f.scene_report || f.scene_report_frames || f.scene_report_size) && !o.scene) {
    return invalid_argument(f.scene_report ? "--scene-report" : f.scene_report_frames ? "--scene-report-frames"
                                                                                       : "--scene-report-size",
                            "", "only with --scene");
  }
  if (const std::optional<std::string>& v = f.scene_report) {
    SINEW_ASSIGN_OR_RETURN(const int c, cli::parse_choice("--scene-report", *v, {"full", "sizes", "off"}));
    o.scene_report = static_cast<BakeOptions::SceneReport>(c);
  }
  if (const std::optional<std::string>& v = f.scene_report_frames) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--scene-report-frames", *v, 1, 100000));
    o.scene_report_run.frames = static_cast<int>(n);
  }
  if (const std::optional<std::string>& v = f.scene_report_size) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--scene-report-size", *v, 8192));
    o.scene_report_run.width = size.width;
    o.scene_report_run.height = size.height;
  }
  if (f.model.empty() && o.model_path.empty()) {
    return invalid_argument("MODEL", "0 given", "expected one model file");
  }
  if (!f.model.empty()) o.model_path = f.model.front();
  if (const std::optional<std::string>& v = f.out) o.out_path = *v;
  if (const std::optional<std::string>& v = f.asset_roots) {
    SINEW_ASSIGN_OR_RETURN(o.gltf.asset_roots, cli::parse_folder_list("--asset-roots", *v));
  }
  SINEW_RETURN_IF_ERROR(f.import_limits.apply(o.gltf.limits));
  if (o.out_path.empty()) return invalid_argument("-o", "", "missing: where to write the pack");
  if (!character::is_pack_path(o.out_path)) return invalid_argument("-o", o.out_path, "expected a .pack file name");
  bool samples_given = false;
  if (const std::optional<std::string>& v = f.pose_space) {
    const std::string mode = *v;
    if (mode == "arbitrary") {
      o.pose_space.mode = anim::PoseSpaceMode::kArbitrary;
    } else if (mode == "limits") {
      o.pose_space.mode = anim::PoseSpaceMode::kLimits;
    } else if (mode == "clips") {
      o.pose_space.mode = anim::PoseSpaceMode::kClips;
    } else if (mode.rfind("clip:", 0) == 0 && mode.size() > 5) {
      o.pose_space.mode = anim::PoseSpaceMode::kClip;
      o.pose_space.clips = {mode.substr(5)};
    } else {
      return invalid_argument("--pose-space", mode, "expected arbitrary, limits, clips or clip:NAME");
    }
  }
  if (const std::optional<std::string>& v = f.clips) {
    if (o.pose_space.mode != anim::PoseSpaceMode::kClips) {
      return invalid_argument("--clips", *v, "only with --pose-space clips");
    }
    SINEW_ASSIGN_OR_RETURN(o.pose_space.clips, cli::parse_list("--clips", *v));
  }
  if (const std::optional<std::string>& v = f.samples) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--samples", *v, 0, anim::kMaxPoseSamples));
    o.pose_space.samples = static_cast<int>(n);
    samples_given = true;
  }
  const bool random_mode =
      o.pose_space.mode == anim::PoseSpaceMode::kArbitrary || o.pose_space.mode == anim::PoseSpaceMode::kLimits;
  if (random_mode && samples_given && o.pose_space.samples == 0) {
    return invalid_argument("--samples", "0", "random pose spaces need at least one sample");
  }
  if (!random_mode && !samples_given && !o.scene) o.pose_space.samples = 0;
  if (random_mode) o.pose_space.every_frame_30hz = false;
  if (random_mode && !samples_given) o.pose_space.samples = 1000;
  if (const std::optional<std::string>& v = f.seed) {
    SINEW_ASSIGN_OR_RETURN(o.pose_space.seed, cli::parse_uint64("--seed", *v));
  }
  if (const std::optional<std::string>& v = f.limits) o.limits_path = *v;
  if (o.pose_space.mode == anim::PoseSpaceMode::kLimits && o.limits_path.empty()) {
    return invalid_argument("--limits", "", "--pose-space limits needs a joint-limits file");
  }
  if (const std::optional<std::string>& v = f.pad) {
    SINEW_ASSIGN_OR_RETURN(const double pad, cli::parse_double("--pad", *v, 0.0, 1.0));
    o.padding = static_cast<float>(pad);
  }
  if (const std::optional<std::string>& v = f.candidates) {
    SINEW_ASSIGN_OR_RETURN(const int c, cli::parse_choice("--candidates", *v, {"all", "influencing"}));
    o.candidates = c == 0 ? rt::CandidateBones::kAll : rt::CandidateBones::kInfluencing;
  }
  if (const std::optional<std::string>& v = f.rigid_bones) {
    SINEW_ASSIGN_OR_RETURN(const int c, cli::parse_choice("--rigid-bones", *v, {"merge", "keep"}));
    o.merge_rigid_bones = c == 0;
  }
  if (const std::optional<std::string>& v = f.sah_intersection_cost) {
    SINEW_ASSIGN_OR_RETURN(const double cost, cli::parse_double("--sah-intersection-cost", *v, 0.01, 100.0));
    o.sah_intersection_cost = static_cast<float>(cost);
    o.sah_intersection_cost_given = true;
  }
  if (const std::optional<std::string>& v = f.pose_clusters) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t k, cli::parse_int("--pose-clusters", *v, 0, rt::kMaxPoseClusters));
    o.pose_clusters = static_cast<std::uint32_t>(k);
  }
  if (const std::optional<std::string>& v = f.bone_trees) {
    SINEW_ASSIGN_OR_RETURN(const int c, cli::parse_choice("--bone-trees", *v, {"kd", "bvh"}));
    o.bone_trees = c == 0 ? rt::BoneTreeKind::kKdTree : rt::BoneTreeKind::kBvh;
  }
  if (const std::optional<std::string>& v = f.bvh_leaf) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--bvh-leaf", *v, 1, 1 << 20));
    o.bvh_leaf = static_cast<int>(n);
  }
  if (const std::optional<std::string>& v = f.threads) {
    SINEW_ASSIGN_OR_RETURN(o.threads, cli::parse_threads("--threads", *v));
  }
  if (const std::optional<std::string>& v = f.max_memory_mib) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t mib, cli::parse_int("--max-memory-mib", *v, 4, std::int64_t{1} << 30));
    o.max_memory_bytes = static_cast<std::size_t>(mib) << 20;
  }
  return o;
}

// --- progress and interruption -----------------------------------------------------

// SIGINT or SIGTERM during a bake cancels it through the progress
// callback: the bake stops, nothing is written, and an existing OUT.pack is
// untouched. During the final write the written file is discarded before
// it replaces anything (character::write_pack's `cancelled`), so no
// temporary file is left either.
std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) { g_interrupted.store(true); }

class ScopedInterruptHandler {
 public:
  ScopedInterruptHandler() {
    g_interrupted.store(false);
    previous_int_ = std::signal(SIGINT, on_interrupt);
    previous_term_ = std::signal(SIGTERM, on_interrupt);
  }
  ~ScopedInterruptHandler() {
    std::signal(SIGINT, previous_int_);
    std::signal(SIGTERM, previous_term_);
  }
  ScopedInterruptHandler(const ScopedInterruptHandler&) = delete;
  ScopedInterruptHandler& operator=(const ScopedInterruptHandler&) = delete;

 private:
  void (*previous_int_)(int) = SIG_DFL;
  void (*previous_term_)(int) = SIG_DFL;
};

// A bar with percent, phase and ETA on a terminal; plain lines otherwise
// (one per phase and per 25%), so logs stay readable. The bake's fraction
// never falls and its phases come in order, each once
// (FuzzyBakeOptions::progress); the percentage printed never falls either.
class ProgressReporter {
 public:
  explicit ProgressReporter(std::ostream& err)
      : err_(err), terminal_(&err == &std::cerr && isatty(STDERR_FILENO) != 0), start_(Clock::now()) {}

  bool update(std::string_view phase, double fraction) {
    if (g_interrupted.load()) return false;
    const double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    const int percent = std::max(static_cast<int>(fraction * 100.0), last_percent_);
    last_percent_ = percent;
    if (terminal_) {
      constexpr int kWidth = 30;
      const int filled = static_cast<int>(fraction * kWidth);
      std::ostringstream line;
      line << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
           << std::string(static_cast<std::size_t>(kWidth - filled), ' ') << "] " << std::setw(3) << percent << "% "
           << std::left << std::setw(10) << phase << std::right;
      if (fraction > 0.02) line << " ETA " << std::fixed << std::setprecision(0) << seconds * (1.0 / fraction - 1.0) << " s  ";
      err_ << line.str() << std::flush;
    } else if (phase != last_phase_ || percent >= next_percent_) {
      err_ << "bake: " << percent << "% " << phase << " (" << std::fixed << std::setprecision(1) << seconds << " s)\n";
      next_percent_ = (percent / 25 + 1) * 25;
    }
    last_phase_ = std::string(phase);
    return true;
  }
  void done() {
    if (terminal_) err_ << "\n";
  }

 private:
  std::ostream& err_;
  bool terminal_;
  Clock::time_point start_;
  std::string last_phase_;
  int next_percent_ = 0;
  int last_percent_ = 0;
};

// SOURCE_DATE_EPOCH (reproducible-builds.org): a fixed bake date, and no
// timings, so the same inputs give a byte-identical pack.
std::optional<std::int64_t> source_date_epoch() {
  const char* text = std::getenv("SOURCE_DATE_EPOCH");
  if (text == nullptr || *text == '\0') return std::nullopt;
  char* end = nullptr;
  const long long value = std::strtoll(text, &end, 10);
  if (end == nullptr || *end != '\0' || value < 0) return std::nullopt;
  return static_cast<std::int64_t>(value);
}

Expected<std::uint64_t> file_hash(const std::string& path) {
  SINEW_ASSIGN_OR_RETURN(const MappedFile file, MappedFile::open(path));
  return checksum64(file.bytes());
}

// Who made a pack from which file, and when (SOURCE_DATE_EPOCH when set).
Expected<character::Provenance> provenance_for(const std::string& model_path) {
  character::Provenance p;
  p.source_name = std::filesystem::path(model_path).filename().string();
  SINEW_ASSIGN_OR_RETURN(p.source_hash, file_hash(model_path));
  p.tool_version = std::string("sinew-editor ") + SINEW_VERSION;
  const auto epoch = source_date_epoch();
  p.bake_unix_time = epoch ? *epoch : static_cast<std::int64_t>(std::time(nullptr));
  return p;
}


int fail(std::ostream& err, std::string_view command, const Status& s) {
  err << "sinew-editor " << command << ": " << s.message() << "\n";
  return 1;
}

int usage_error(std::ostream& err, std::string_view command, const Status& s) {
  return cli::usage_error("sinew-editor " + std::string(command), s, err);
}

// --- inspect ------------------------------------------------------------------------

struct TreeFigures {
  int max_depth = 0;
  double mean_depth_of_leaves = 0.0;
  std::size_t leaves = 0;
};

// Depths of one bone's tree (iterative: loaded trees are already validated).
// Depth figures of a tree whose node n is a leaf when leaf(n) and has the
// children children(n) otherwise.
template <class IsLeaf, class Children>
TreeFigures tree_figures(std::size_t node_count, IsLeaf&& leaf, Children&& children) {
  TreeFigures f;
  if (node_count == 0) return f;
  std::vector<std::pair<std::uint32_t, int>> stack{{0u, 0}};
  double depth_sum = 0.0;
  while (!stack.empty()) {
    const auto [node, depth] = stack.back();
    stack.pop_back();
    f.max_depth = std::max(f.max_depth, depth);
    if (leaf(node)) {
      ++f.leaves;
      depth_sum += depth;
      continue;
    }
    const auto [below, above] = children(node);
    stack.push_back({below, depth + 1});
    stack.push_back({above, depth + 1});
  }
  f.mean_depth_of_leaves = f.leaves ? depth_sum / static_cast<double>(f.leaves) : 0.0;
  return f;
}

TreeFigures tree_figures(const rt::BvhView& tree) {
  return tree_figures(
      tree.nodes.size(), [&](std::uint32_t n) { return tree.nodes[n].is_leaf(); },
      [&](std::uint32_t n) { return std::pair{tree.nodes[n].first, tree.nodes[n].first + 1}; });
}

TreeFigures tree_figures(const rt::KdTreeView& tree) {
  return tree_figures(
      tree.nodes.size(), [&](std::uint32_t n) { return tree.nodes[n].is_leaf(); },
      [&](std::uint32_t n) { return std::pair{n + 1, tree.nodes[n].above_child()}; });
}

std::string utc_text(std::int64_t unix_time) {
  const std::time_t t = static_cast<std::time_t>(unix_time);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

Json shown_all(const std::vector<std::string>& texts) {
  Json out = Json::array();
  for (const std::string& t : texts) out.push_back(shown(t));
  return out;
}

// A measured number for people: 3 significant digits, never an exponent
// ("1.94", "23.2", "566", "0.0667", "131"; "1235" stays whole). With
// `scale`, as many decimals as 3 significant digits of `scale` take (the
// corners of a box to its size: 0.00 rather than -0.000000231).
std::string number_text(double value, double scale = 0.0) {
  if (!std::isfinite(value)) return value > 0 ? "inf" : value < 0 ? "-inf" : "nan";
  if (value == 0.0 && scale == 0.0) return "0";
  const double magnitude = scale > 0.0 ? scale : std::abs(value);
  std::ostringstream text;
  if (magnitude >= 100.0) {
    text << std::fixed << std::setprecision(0) << value;
  } else {
    const int decimals = 2 - static_cast<int>(std::floor(std::log10(magnitude)));
    text << std::fixed << std::setprecision(std::min(decimals, 12)) << value;
  }
  std::string t = text.str();
  if (t[0] == '-' && t.find_first_of("123456789") == std::string::npos) t.erase(0, 1);  // no "-0.00"
  return t;
}

// What each section holds, in a few words (docs/PACK_FORMAT.md has the
// layouts); "" for a tag this build does not know.
std::string_view section_meaning(std::string_view id) {
  static constexpr std::pair<std::string_view, std::string_view> kMeanings[] = {
      {"SKEL", "skeleton"},
      {"MESH", "skinned mesh"},
      {"CLIP", "animation clips"},
      {"LIMT", "joint limits"},
      {"POSE", "pose space baked over"},
      {"PROV", "provenance"},
      {"FRAM", "framing: up axis, rest bounds"},
      {"TEXR", "material textures, their mip chains"},
      {"FZHD", "fuzzy header"},
      {"FTBN", "each triangle's bone"},
      {"FBTR", "bone trees"},
      {"FNOD", "kd-tree nodes"},
      {"FBVN", "BVH nodes"},
      {"FITM", "leaf items"},
      {"FVCB", "escape checks per vertex"},
      {"FVCK", "escape checks"},
      {"FTCK", "triangle corners' checks"},
      {"FCHD", "pose-cluster header"},
      {"FCLB", "clusters per bone"},
      {"FCLS", "pose clusters"},
      {"FCKR", "check ranks"},
      {"FCLX", "cluster boxes"},
      {"FFBB", "feature bones per bone"},
      {"FFBN", "feature bones"},
      {"FCCN", "cluster centres"},
  };
  for (const auto& [tag, meaning] : kMeanings) {
    if (tag == id) return meaning;
  }
  return "";
}

// A byte count for people: "83 bytes", "4.0 KiB", "872 KiB", "1.23 MiB".
std::string size_text(std::uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
  const char* const units[] = {"KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes) / 1024.0;
  int unit = 0;
  while (value >= 1024.0 && unit < 3) {
    value /= 1024.0;
    ++unit;
  }
  return number_text(value) + " " + units[unit];
}

Json inspect_json(const character::Pack& pack) {
  const character::Model& m = pack.model();
  Json sections = Json::array();
  for (const SectionInfo& s : pack.reader().sections()) {
    const std::string id = section_id_name(s.id);
    sections.push_back({{"id", shown(id)}, {"version", s.version}, {"bytes", s.size},
                        {"holds", std::string(section_meaning(id))}});
  }
  Json clips = Json::array();
  for (const anim::Clip& c : m.clips) clips.push_back({{"name", shown(c.name())}, {"seconds", c.duration()}});
  const character::PoseSpaceRecord& ps = pack.pose_space();
  const character::Provenance& p = pack.provenance();
  Json out = {
      {"file", shown(pack.reader().name())},
      {"bytes", pack.reader().bytes().size()},
      {"format_version", std::to_string(pack.reader().version().major) + "." +
                             std::to_string(pack.reader().version().minor)},
      {"sections", sections},
      {"model", {{"joints", m.skeleton.joint_count()}, {"vertices", m.mesh.vertex_count()},
                 {"triangles", m.mesh.triangle_count()}, {"materials", m.mesh.material_colors.size()},
                 {"clips", clips}, {"joint_limits", !pack.limits().empty()}}},
      {"pose_space", {{"mode", std::string(anim::pose_space_mode_name(ps.desc.mode))}, {"clips", shown_all(ps.desc.clips)},
                      {"samples_requested", ps.desc.samples}, {"every_frame_30hz", ps.desc.every_frame_30hz},
                      {"seed", ps.desc.seed}, {"padding", ps.padding},
                      {"candidates", ps.candidates == rt::CandidateBones::kAll ? "all" : "influencing"}}},
      {"framing", {{"up_axis", pack.framing().up_axis},
                   {"rest_bounds", {{"min", {pack.framing().rest_bounds.lower.x, pack.framing().rest_bounds.lower.y,
                                             pack.framing().rest_bounds.lower.z}},
                                    {"max", {pack.framing().rest_bounds.upper.x, pack.framing().rest_bounds.upper.y,
                                             pack.framing().rest_bounds.upper.z}}}},
                   {"stored", pack.framing_stored()}}},
      {"provenance", {{"source", shown(p.source_name)}, {"source_xxh3", p.source_hash}, {"tool", shown(p.tool_version)},
                      {"bake_date", utc_text(p.bake_unix_time)}, {"bake_unix_time", p.bake_unix_time},
                      {"pose_sampling_ms", p.pose_sampling_ms}, {"sampling_ms", p.sampling_ms},
                      {"assignment_ms", p.assignment_ms}, {"build_ms", p.build_ms}}},
  };
  if (!pack.has_fuzzy()) {
    out["fuzzy"] = nullptr;
    return out;
  }
  const rt::FuzzyBakeStats& st = pack.fuzzy_stats();
  const rt::FuzzyCharacterView& f = pack.fuzzy();
  Json bones = Json::array();
  int max_depth = 0;
  double depth_sum = 0.0;
  std::size_t leaves = 0;
  for (std::uint32_t b = 0; b < f.bone_count; ++b) {
    const TreeFigures t =
        f.has_bvhs() ? tree_figures(f.bvh_view(f.bone_trees[b])) : tree_figures(f.bone_tree(b));
    max_depth = std::max(max_depth, t.max_depth);
    depth_sum += t.mean_depth_of_leaves * static_cast<double>(t.leaves);
    leaves += t.leaves;
    bones.push_back({{"bone", shown(m.skeleton.names()[b])}, {"triangles", f.bone_trees[b].triangle_count},
                     {"nodes", f.bone_trees[b].node_count}, {"max_depth", t.max_depth}});
  }
  out["fuzzy"] = {{"pose_samples", st.sample_count},
                  {"fuzzy_area", st.fuzzy_area},
                  {"rest_area", st.rest_area},
                  {"fuzzy_area_ratio", st.rest_area > 0.0 ? st.fuzzy_area / st.rest_area : 0.0},
                  {"triangles_per_leaf", st.mean_items_per_leaf},
                  {"bone_trees", f.has_bvhs() ? "bvh" : "kd"},
                  {"nodes", f.has_bvhs() ? f.bvh_nodes.size() : f.nodes.size()},
                  {"leaf_items", f.items.size()},
                  {"max_depth", max_depth},
                  {"mean_leaf_depth", leaves ? depth_sum / static_cast<double>(leaves) : 0.0},
                  {"merge_rigid_bones", st.merge_rigid_bones},
                  {"merged_bones", st.merged_bones},
                  {"clusters_per_bone", st.clusters_per_bone},
                  {"clusters", f.clusters.size()},
                  {"cluster_fuzzy_area_ratio", st.rest_area > 0.0 ? st.cluster_fuzzy_area / st.rest_area : 0.0},
                  {"bones", bones}};
  return out;
}

void print_inspect(const Json& j, std::ostream& out) {
  const auto num = [](const Json& v) { return number_text(v.get<double>()); };
  out << j["file"].get<std::string>() << ": " << size_text(j["bytes"].get<std::uint64_t>()) << " ("
      << j["bytes"] << " bytes), pack format " << j["format_version"].get<std::string>() << ", "
      << j["sections"].size() << " sections\n";
  for (const Json& s : j["sections"]) {
    const std::string id = s["id"].get<std::string>();
    const std::string_view meaning = section_meaning(id);
    out << "  " << id << " v" << s["version"] << "  " << std::left << std::setw(10)
        << size_text(s["bytes"].get<std::uint64_t>()) << std::right
        << (meaning.empty() ? std::string() : "  " + std::string(meaning)) << "\n";
  }
  const Json& m = j["model"];
  out << "model: " << m["joints"] << " joints, " << m["vertices"] << " vertices, " << m["triangles"] << " triangles, "
      << m["materials"] << " materials, " << m["clips"].size() << " clips"
      << (m["joint_limits"].get<bool>() ? ", joint limits" : "") << "\n";
  for (const Json& c : m["clips"]) out << "  clip " << c["name"].get<std::string>() << " (" << num(c["seconds"]) << " s)\n";
  const Json& fr = j["framing"];
  double scale = 0.0;  // the box's largest coordinate: its corners to 3 significant digits of it
  for (const char* c : {"min", "max"}) {
    for (int a = 0; a < 3; ++a) scale = std::max(scale, std::abs(fr["rest_bounds"][c][a].get<double>()));
  }
  const auto corner = [&](const Json& v) {
    const auto n = [&](int a) { return number_text(v[a].get<double>(), scale); };
    return "(" + n(0) + ", " + n(1) + ", " + n(2) + ")";
  };
  out << "framing: stands along +" << (fr["up_axis"].get<int>() == 1 ? "Y" : "Z") << ", rest bounds "
      << corner(fr["rest_bounds"]["min"]) << " to " << corner(fr["rest_bounds"]["max"])
      << (fr["stored"].get<bool>() ? "" : " (computed: the pack predates FRAM)") << "\n";
  const Json& ps = j["pose_space"];
  std::string clip_names;
  for (const Json& c : ps["clips"]) clip_names += (clip_names.empty() ? " (" : ", ") + c.get<std::string>();
  if (!clip_names.empty()) clip_names += ")";
  out << "pose space: " << ps["mode"].get<std::string>() << clip_names << ", samples requested " << ps["samples_requested"]
      << ", seed " << ps["seed"] << ", padding " << num(ps["padding"]) << ", candidates "
      << ps["candidates"].get<std::string>() << "\n";
  const Json& p = j["provenance"];
  out << "provenance: " << p["source"].get<std::string>() << " (xxh3 " << std::hex << p["source_xxh3"].get<std::uint64_t>()
      << std::dec << "), " << p["tool"].get<std::string>() << ", baked " << p["bake_date"].get<std::string>() << "\n"
      << "bake times: pose sampling " << num(p["pose_sampling_ms"]) << " ms, boxes " << num(p["sampling_ms"])
      << " ms, assignment " << num(p["assignment_ms"]) << " ms, trees " << num(p["build_ms"]) << " ms\n";
  if (j["fuzzy"].is_null()) {
    out << "fuzzy trees: none (a model-only pack)\n";
    return;
  }
  const Json& f = j["fuzzy"];
  out << "fuzzy trees: " << f["pose_samples"] << " pose samples, fuzzy area " << num(f["fuzzy_area_ratio"])
      << "x the rest pose's, " << num(f["triangles_per_leaf"]) << " triangles per leaf, " << f["nodes"]
      << " nodes, depth " << f["max_depth"] << " max / " << num(f["mean_leaf_depth"]) << " mean leaf; "
      << (f["merge_rigid_bones"].get<bool>() ? std::to_string(f["merged_bones"].get<std::uint32_t>()) +
                                                   " bones merged into their parents' trees"
                                             : std::string("rigid bones kept"))
      << "\n";
  if (f["clusters"].get<std::size_t>() > 0) {
    out << "pose-space clusters: " << f["clusters"] << " (up to " << f["clusters_per_bone"]
        << " a bone), fuzzy area " << num(f["cluster_fuzzy_area_ratio"])
        << "x the rest pose's averaged over each bone's clusters\n";
  }
}

// "38.2%" (one decimal; "0%" for none, "< 0.1%" for a few).
std::string percent_text(double share) {
  if (share <= 0.0) return "0%";
  if (share < 0.001) return "< 0.1%";
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << 100.0 * share << "%";
  return text.str();
}

// Whether the pose space sampled `clip` (random spaces sample no clip).
bool pose_space_has_clip(const anim::PoseSpaceDesc& space, const std::string& clip) {
  switch (space.mode) {
    case anim::PoseSpaceMode::kClips:
      return space.clips.empty() || std::find(space.clips.begin(), space.clips.end(), clip) != space.clips.end();
    case anim::PoseSpaceMode::kClip:
      return !space.clips.empty() && space.clips.front() == clip;
    default:
      return false;
  }
}

// No silent cliffs: how much of the rest pose, and of each clip the bake
// was not given, lies outside the pose space just baked. Those triangles
// render exactly, through the per-frame fallback tree, at its cost.
constexpr std::size_t kReportPosesPerClip = 30;

Status report_outside(const character::Model& model, const anim::PoseSpaceDesc& space,
                      const rt::FuzzyCharacterView& fuzzy, JobSystem& jobs, std::ostream& out) {
  SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> rest, character::rest_skinning(model));
  SINEW_ASSIGN_OR_RETURN(const character::OutsideShare at_rest, character::triangles_outside(model, fuzzy, rest, jobs));
  out << "rest pose: " << percent_text(at_rest.max) << " of triangles outside the pose space"
      << (at_rest.max > 0.0 ? " (they will render through the fallback)" : "") << "\n";
  bool any_outside = at_rest.max > 0.0;
  for (const anim::Clip& clip : model.clips) {
    if (pose_space_has_clip(space, clip.name())) continue;
    SINEW_ASSIGN_OR_RETURN(const std::vector<Affine3> poses, character::clip_poses(model, clip, kReportPosesPerClip));
    SINEW_ASSIGN_OR_RETURN(const character::OutsideShare share,
                           character::triangles_outside(model, fuzzy, poses, jobs));
    out << "clip " << shown(clip.name()) << " (not baked): " << percent_text(share.mean)
        << " of triangles outside the pose space on average, " << percent_text(share.max) << " at worst over "
        << share.poses << (share.poses == 1 ? " pose" : " poses") << "\n";
    any_outside |= share.max > 0.0;
  }
  if (any_outside) {
    out << "poses outside the pose space render exactly but slower, through a tree built each frame: "
           "bake the poses you will play (docs/EDITOR.md, \"Why is my character slow?\")\n";
  }
  return {};
}

// The process's peak resident set so far (getrusage), in KiB; 0 if unknown.
long max_rss_kib() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return usage.ru_maxrss;  // Linux reports KiB
}

// The estimate counts the bake's large buffers; the RSS peak is what the
// process really touched (it includes the loaded model and the allocator's
// slack, and only grows, so a bake below an earlier peak adds nothing).
void print_bake_memory(const character::BakeMemory& m, long rss_before_kib, long rss_after_kib, std::ostream& out) {
  const auto mib = [](double bytes) { return bytes / (1024.0 * 1024.0); };
  out << std::fixed << std::setprecision(1) << "bake memory: peak " << mib(static_cast<double>(m.peak()))
      << " MiB estimated (pose samples " << mib(static_cast<double>(m.pose_samples)) << " MiB + fuzzy bake "
      << mib(static_cast<double>(m.fuzzy_peak)) << " MiB); process peak RSS "
      << static_cast<double>(rss_after_kib) / 1024.0 << " MiB (" << static_cast<double>(rss_before_kib) / 1024.0
      << " MiB before the bake)\n"
      << std::defaultfloat << std::flush;
}

}  // namespace

int run_bake(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto line = bake_command_line();
  const BakeFlags flags(*line);
  auto parsed = parse_bake_options(args, *line, flags);
  if (!parsed.ok()) {
    // A scene recipe is read while parsing: an error naming a file is about
    // its contents (exit 1), one naming only an option is a usage error.
    if (!parsed.status().file().empty()) return fail(err, "bake", parsed.status());
    return usage_error(err, "bake", parsed.status());
  }
  const BakeOptions& o = *parsed;
  if (o.help) {
    out << line->help();
    return 0;
  }
  const auto start = Clock::now();
  auto model = load_model(o.model_path, o.gltf);
  if (!model.ok()) return fail(err, "bake", model.status());
  for (const std::string& warning : model->warnings) err << "sinew-editor bake: warning: " << warning << "\n";
  // The scene's report bakes the whole model too.
  std::optional<character::Model> whole;
  if (o.scene && o.scene_report != BakeOptions::SceneReport::kOff) whole = *model;
  if (o.scene) {  // model only what the scene plays
    auto kept = keep_recipe_clips(*model, *o.scene);
    if (!kept.ok()) return fail(err, "bake", kept.status());
    model = std::move(kept);
  }
  character::BakeRequest request;
  request.pose_space = o.pose_space;
  request.fuzzy.padding = o.padding;
  request.fuzzy.candidates = o.candidates;
  request.fuzzy.merge_rigid_bones = o.merge_rigid_bones;
  request.fuzzy.kd.intersection_cost = o.sah_intersection_cost;
  request.fuzzy.fine_mesh_cost = !o.sah_intersection_cost_given;
  request.fuzzy.pose_clusters = o.pose_clusters.value_or(0);
  request.fuzzy.fine_mesh_clusters = !o.pose_clusters.has_value();
  request.fuzzy.bone_trees = o.bone_trees;
  request.fuzzy.bvh.max_leaf_items = o.bvh_leaf;
  request.max_memory_bytes = o.max_memory_bytes;
  request.fuzzy.memory_budget_bytes = std::min(request.fuzzy.memory_budget_bytes, o.max_memory_bytes / 4);
  if (!o.limits_path.empty()) {
    auto limits = anim::load_joint_limits(o.limits_path, model->skeleton);
    if (!limits.ok()) return fail(err, "bake", limits.status());
    request.limits = std::move(*limits);
  }
  ProgressReporter progress(err);
  request.fuzzy.progress = [&](std::string_view phase, double fraction) { return progress.update(phase, fraction); };
  JobSystem jobs(o.threads);
  out << "baking " << o.model_path << " (" << model->mesh.triangle_count() << " triangles, "
      << model->skeleton.joint_count() << " joints) over the " << anim::pose_space_mode_name(o.pose_space.mode)
      << " pose space on " << jobs.thread_count() << " threads\n"
      << std::flush;
  const long rss_before_kib = max_rss_kib();
  // Until the pack is in place, an interrupt cancels the bake or the write.
  std::optional<ScopedInterruptHandler> interrupts(std::in_place);
  const auto interrupted = [&] {
    err << "sinew-editor bake: interrupted; " << o.out_path << " was not written (an existing file is unchanged)\n";
    return 1;
  };
  Expected<character::InMemoryBake> bake = character::bake_in_memory(*model, request, jobs);
  progress.done();
  if (bake.ok()) print_bake_memory(bake->memory, rss_before_kib, max_rss_kib(), out);
  if (!bake.ok()) {
    if (bake.status().code() == ErrorCode::kCancelled) return interrupted();
    return fail(err, "bake", bake.status());
  }

  character::PackContents contents;
  contents.model = &*model;
  contents.limits = request.limits;
  contents.fuzzy = &bake->fuzzy;
  contents.pose_space.desc = o.pose_space;
  contents.pose_space.padding = o.padding;
  contents.pose_space.candidates = o.candidates;
  auto provenance = provenance_for(o.model_path);
  if (!provenance.ok()) return fail(err, "bake", provenance.status());
  character::Provenance& p = contents.provenance = std::move(*provenance);
  if (!source_date_epoch()) {  // reproducible bakes record no timings
    p.pose_sampling_ms = bake->pose_sampling_ms;
    p.sampling_ms = bake->fuzzy.stats.sampling_ms;
    p.assignment_ms = bake->fuzzy.stats.assignment_ms;
    p.build_ms = bake->fuzzy.stats.build_ms;
  }
  if (Status s = character::write_pack(o.out_path, contents, [] { return g_interrupted.load(); }); !s.ok()) {
    if (s.code() == ErrorCode::kCancelled) return interrupted();
    return fail(err, "bake", s);
  }
  interrupts.reset();  // the pack is in place: an interrupt stops the program again
  const rt::FuzzyBakeStats& st = bake->fuzzy.stats;
  out << "wrote " << o.out_path << ": " << std::filesystem::file_size(o.out_path) << " bytes, " << st.sample_count
      << " pose samples, fuzzy area " << std::fixed << std::setprecision(3)
      << (st.rest_area > 0.0 ? st.fuzzy_area / st.rest_area : 0.0) << "x rest, " << std::setprecision(2)
      << st.mean_items_per_leaf << " triangles per leaf, " << rigid_bones_text(st) << ", " << std::setprecision(0)
      << ms_since(start) << " ms\n";
  if (st.clusters_per_bone > 0) {
    out << "pose-space clusters: " << st.cluster_count << " (up to " << st.clusters_per_bone << " a bone), fuzzy area "
        << std::setprecision(3) << (st.rest_area > 0.0 ? st.cluster_fuzzy_area / st.rest_area : 0.0)
        << "x rest averaged over each bone's clusters, " << std::setprecision(0) << st.clustering_ms
        << " ms clustering and their boxes\n";
  }
  out << std::defaultfloat;
  if (Status s = report_outside(*model, o.pose_space, bake->fuzzy.view(), jobs, out); !s.ok()) {
    return fail(err, "bake", s);
  }
  if (whole) {
    SceneSavingsOptions run = o.scene_report_run;
    run.threads = o.threads;
    if (o.scene_report == BakeOptions::SceneReport::kSizes) run.frames = 0;
    out << "measuring what the scene saved (a bake of the whole model"
        << (run.frames > 0 ? ", and both rendered" : "") << ")...\n"
        << std::flush;
    auto savings = measure_scene_savings(*whole, *o.scene, o.out_path, request, run, jobs);
    if (!savings.ok()) return fail(err, "bake", savings.status());
    out << describe(*savings, run, jobs.thread_count());
  }
  return 0;
}

int run_subdivide(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  cli::CommandLine line("sinew-editor subdivide",
                        "Splits every triangle into four at its edge midpoints, L times; shared edges\n"
                        "share their midpoint (no cracks), midpoints average the attributes and merge the skin\n"
                        "weights. Writes a model-only pack, which `bake` takes as its MODEL.\n");
  const auto& model_arg = line.positionals("MODEL", ".gltf, .glb, .cfg (Cal3D) or a .pack", 1);
  const auto& levels_text = line.option("--levels", "L", "subdivision levels (1.." +
                                                             std::to_string(kMaxSubdivisionLevels) + "; required)");
  const auto& out_path = line.option("-o,--out", "OUT.pack", "the model-only pack to write (required)");
  if (const auto done = cli::help_or_usage_error(line, line.parse(args), out, err)) return *done;
  if (model_arg.empty()) return usage_error(err, "subdivide", invalid_argument("MODEL", "", "expected one model file"));
  if (!levels_text) return usage_error(err, "subdivide", invalid_argument("--levels", "", "missing"));
  if (!out_path || !character::is_pack_path(*out_path)) {
    return usage_error(err, "subdivide", invalid_argument("-o", out_path.value_or(""), "expected a .pack file name"));
  }
  auto levels = cli::parse_int("--levels", *levels_text, 1, kMaxSubdivisionLevels);
  if (!levels.ok()) return usage_error(err, "subdivide", levels.status());
  const std::string& model_path = model_arg.front();
  auto model = load_model(model_path);
  if (!model.ok()) return fail(err, "subdivide", model.status());
  for (const std::string& warning : model->warnings) err << "sinew-editor subdivide: warning: " << warning << "\n";
  auto finer = subdivide(*model, static_cast<int>(*levels));
  if (!finer.ok()) return fail(err, "subdivide", finer.status());
  character::PackContents contents;
  contents.model = &*finer;
  auto provenance = provenance_for(model_path);
  if (!provenance.ok()) return fail(err, "subdivide", provenance.status());
  contents.provenance = std::move(*provenance);
  if (Status s = character::write_pack(*out_path, contents); !s.ok()) return fail(err, "subdivide", s);
  out << "wrote " << *out_path << ": " << finer->mesh.vertex_count() << " vertices, " << finer->mesh.triangle_count()
      << " triangles (from " << model->mesh.triangle_count() << ", " << *levels << " levels)\n";
  return 0;
}

int run_inspect(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  cli::CommandLine line("sinew-editor inspect",
                        "Sizes, counts, pose space, fuzzy area, tree depths and provenance of a pack.\n");
  const auto& pack_arg = line.positionals("PACK", "the content pack", 1);
  const bool& json = line.flag("--json", "print it as JSON");
  if (const auto done = cli::help_or_usage_error(line, line.parse(args), out, err)) return *done;
  if (pack_arg.empty()) return usage_error(err, "inspect", invalid_argument("PACK", "", "expected one pack file"));
  auto pack = character::Pack::open(pack_arg.front());
  if (!pack.ok()) return fail(err, "inspect", pack.status());
  const Json j = inspect_json(*pack);
  if (json) {
    out << j.dump(2) << "\n";
  } else {
    print_inspect(j, out);
  }
  return 0;
}

int run_validate(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  cli::CommandLine line("sinew-editor validate",
                        "Checks the container (checksums, bounds, alignment) and every section's contents\n"
                        "(counts, indices, finite values, kd-tree links and depth); exit 0 when valid.\n");
  const auto& pack_arg = line.positionals("PACK", "the content pack", 1);
  if (const auto done = cli::help_or_usage_error(line, line.parse(args), out, err)) return *done;
  if (pack_arg.empty()) return usage_error(err, "validate", invalid_argument("PACK", "", "expected one pack file"));
  const auto start = Clock::now();
  auto pack = character::Pack::open(pack_arg.front());
  const double load_ms = ms_since(start);
  if (!pack.ok()) return fail(err, "validate", pack.status());
  out << pack_arg.front() << ": valid, checked in " << std::fixed << std::setprecision(1) << load_ms
      << " ms (" << pack->reader().section_count() << " sections, "
      << pack->model().mesh.triangle_count() << " triangles, "
      << (pack->has_fuzzy() ? "fuzzy trees of " + std::to_string(pack->fuzzy().bone_count) + " bones"
                            : std::string("model only"))
      << ")\n";
  return 0;
}

}  // namespace sinew::editor
