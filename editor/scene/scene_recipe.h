// Scene recipes (content/scenes/*.json): what a scene needs from a
// character, so that a bake models only that ("the runtime computes only
// what a scene asks for"). A recipe names the model, the clips the scene
// plays and how the pose space over them is sampled:
//
//   {
//     "model": "../../../shared/content/cal3d/cally/cally.cfg",  // relative to the recipe
//     "clips": ["walk", "jog", "wave"],
//     "pose_space": {"samples": 0, "every_frame_30hz": true, "padding": 0.0}
//   }
//
// `sinew-editor bake --scene RECIPE` bakes the pose space of those clips
// only and stores only those clips in the pack.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "character/model.h"
#include "runtime/core/expected.h"

namespace sinew::editor {

struct SceneRecipe {
  std::string source;      // the recipe file
  std::string model_path;  // resolved against the recipe's folder; may be empty (given on the command line)
  std::vector<std::string> clips;  // non-empty, unique
  int samples = 0;                 // at most this many key times per clip (0 = all)
  bool every_frame_30hz = true;
  float padding = 0.0f;
};

// Errors (kInvalidData / kIoError) name the recipe file and the field:
// `walk.json: clips[1] = 7: expected a clip name`.
Expected<SceneRecipe> parse_scene_recipe(std::string_view json, const std::string& source);
Expected<SceneRecipe> load_scene_recipe(const std::string& path);

// `model` keeping only the recipe's clips, in the recipe's order.
// kNotFound names a clip the model does not have, and lists the ones it has.
Expected<character::Model> keep_recipe_clips(const character::Model& model, const SceneRecipe& recipe);

}  // namespace sinew::editor
