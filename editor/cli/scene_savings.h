// What `sinew-editor bake --scene` saved, measured in the same run: the
// scene's pack (only the recipe's clips, their pose space, rigid and
// triangle-less bones merged into their parents' trees) against a bake of
// the whole model (every clip in the pack and the pose space, every bone its
// own tree), both written and both rendered playing the recipe's first clip
// side by side (render_command.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/model.h"
#include "editor/scene/scene_recipe.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"

namespace sinew::editor {

struct SceneSavingsOptions {
  int frames = 30;  // rendered per pack; 0: no fps measured
  int width = 1024;
  int height = 1024;
  int threads = 0;  // 0: all cores
};

struct SceneSavings {
  std::size_t clips = 0;                    // the whole model's
  std::vector<std::string> dropped_clips;   // not in the recipe
  std::uint32_t scene_trees = 0;            // bone trees holding triangles: top-level objects per instance
  std::uint32_t whole_trees = 0;
  std::uint32_t scene_samples = 0;          // pose samples
  std::uint32_t whole_samples = 0;
  std::uintmax_t scene_bytes = 0;           // pack files
  std::uintmax_t whole_bytes = 0;
  std::string clip;                         // the clip rendered
  double scene_fps = 0.0;                   // 0: not measured
  double whole_fps = 0.0;
};

// `whole` is the model as imported (every clip); `scene_pack` the pack just
// written from `scene_request`. The whole model's bake takes the request's
// options but every clip (at the recipe's sampling) and keeps rigid bones;
// its pack goes to a temporary file, removed before returning. Errors name
// the file and the step.
Expected<SceneSavings> measure_scene_savings(const character::Model& whole, const SceneRecipe& recipe,
                                             const std::string& scene_pack,
                                             const character::BakeRequest& scene_request,
                                             const SceneSavingsOptions& options, JobSystem& jobs);

// The report's lines, e.g.
//   scene drops 2 of 5 clips (jog, strut)
//   scene bone trees: 20 per instance instead of 37
//   scene pack: 522408 bytes instead of 1160188 (-55%), 159 pose samples instead of 402
//   scene fps (clip 'walk', 1024x1024, 30 frames, 2 threads): 81.0 instead of 76.2 (+6%)
std::string describe(const SceneSavings& savings, const SceneSavingsOptions& options, int threads);

}  // namespace sinew::editor
