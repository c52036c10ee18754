#include "editor/cli/scene_savings.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <span>
#include <sstream>
#include <system_error>

#include "character/pack.h"
#include "editor/cli/render_command.h"

namespace sinew::editor {
namespace {

std::uint32_t trees_with_triangles(std::span<const rt::BoneTree> trees) {
  return static_cast<std::uint32_t>(
      std::count_if(trees.begin(), trees.end(), [](const rt::BoneTree& t) { return t.triangle_count > 0; }));
}

// Removes the file when it goes out of scope (the whole model's pack).
struct TemporaryFile {
  std::string path;
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};

Expected<double> render_fps(const std::string& pack, const std::string& clip, const SceneSavingsOptions& o) {
  RenderOptions r;
  r.model_path = pack;
  r.clip = clip;
  r.width = o.width;
  r.height = o.height;
  r.frames = o.frames;
  r.threads = o.threads;
  SINEW_ASSIGN_OR_RETURN(const RenderOutputs out, render_model(r));
  return out.stats.fps;
}

// "+6%" / "-55%": b against a.
std::string change(double a, double b) {
  if (!(a > 0.0)) return "";
  const long percent = std::lround(100.0 * (b - a) / a);
  return " (" + std::string(percent > 0 ? "+" : "") + std::to_string(percent) + "%)";
}

}  // namespace

Expected<SceneSavings> measure_scene_savings(const character::Model& whole, const SceneRecipe& recipe,
                                             const std::string& scene_pack,
                                             const character::BakeRequest& scene_request,
                                             const SceneSavingsOptions& options, JobSystem& jobs) {
  SceneSavings s;
  s.clips = whole.clips.size();
  for (const anim::Clip& clip : whole.clips) {
    if (std::find(recipe.clips.begin(), recipe.clips.end(), clip.name()) == recipe.clips.end()) {
      s.dropped_clips.push_back(clip.name());
    }
  }
  SINEW_ASSIGN_OR_RETURN(const character::Pack scene, character::Pack::open(scene_pack));
  if (!scene.has_fuzzy()) return make_error(ErrorCode::kInvalidData, scene_pack, "fuzzy", "none", "expected a baked pack");
  std::error_code size_error;
  s.scene_bytes = std::filesystem::file_size(scene_pack, size_error);
  if (size_error) return make_error(ErrorCode::kIoError, scene_pack, "size", "", size_error.message());
  s.scene_trees = trees_with_triangles(scene.fuzzy().bone_trees);
  s.scene_samples = scene.fuzzy_stats().sample_count;

  // The whole model: every clip at the recipe's sampling, every bone its own tree.
  character::BakeRequest request = scene_request;
  request.pose_space.clips.clear();
  request.fuzzy.merge_rigid_bones = false;
  request.fuzzy.progress = nullptr;
  SINEW_ASSIGN_OR_RETURN(const character::InMemoryBake bake, character::bake_in_memory(whole, request, jobs));
  s.whole_trees = trees_with_triangles(bake.fuzzy.bone_trees);
  s.whole_samples = bake.fuzzy.stats.sample_count;
  const TemporaryFile whole_pack{(std::filesystem::temp_directory_path() /
                                  ("sinew-scene-whole-" + std::to_string(::getpid()) + ".pack"))
                                     .string()};
  character::PackContents contents;
  contents.model = &whole;
  contents.limits = request.limits;
  contents.fuzzy = &bake.fuzzy;
  contents.pose_space.desc = request.pose_space;
  contents.pose_space.padding = request.fuzzy.padding;
  contents.pose_space.candidates = request.fuzzy.candidates;
  SINEW_RETURN_IF_ERROR(character::write_pack(whole_pack.path, contents));
  s.whole_bytes = std::filesystem::file_size(whole_pack.path, size_error);
  if (size_error) return make_error(ErrorCode::kIoError, whole_pack.path, "size", "", size_error.message());

  s.clip = recipe.clips.front();
  if (options.frames > 0) {
    // Side by side: each pack twice, alternating, the better run of each
    // (the machine's load drifts; the better run is the least disturbed).
    for (int round = 0; round < 2; ++round) {
      SINEW_ASSIGN_OR_RETURN(const double scene_fps, render_fps(scene_pack, s.clip, options));
      SINEW_ASSIGN_OR_RETURN(const double whole_fps, render_fps(whole_pack.path, s.clip, options));
      s.scene_fps = std::max(s.scene_fps, scene_fps);
      s.whole_fps = std::max(s.whole_fps, whole_fps);
    }
  }
  return s;
}

std::string describe(const SceneSavings& s, const SceneSavingsOptions& options, int threads) {
  std::ostringstream out;
  out << "scene drops " << s.dropped_clips.size() << " of " << s.clips << " clips";
  if (!s.dropped_clips.empty()) {
    out << " (";
    for (std::size_t i = 0; i < s.dropped_clips.size(); ++i) out << (i > 0 ? ", " : "") << s.dropped_clips[i];
    out << ")";
  }
  out << "\nscene bone trees: " << s.scene_trees << " per instance instead of " << s.whole_trees
      << " (top-level objects, each a ray transform)\n"
      << "scene pack: " << s.scene_bytes << " bytes instead of " << s.whole_bytes
      << change(static_cast<double>(s.whole_bytes), static_cast<double>(s.scene_bytes)) << ", " << s.scene_samples
      << " pose samples instead of " << s.whole_samples << "\n";
  if (s.scene_fps > 0.0 && s.whole_fps > 0.0) {
    out.setf(std::ios::fixed);
    out.precision(1);
    out << "scene fps (clip '" << s.clip << "', " << options.width << "x" << options.height << ", " << options.frames
        << " frames, " << threads << " threads, the better of two alternating runs): " << s.scene_fps
        << " instead of " << s.whole_fps << change(s.whole_fps, s.scene_fps) << "\n";
  }
  return out.str();
}

}  // namespace sinew::editor
