#include "editor/scene/scene_recipe.h"
#include "runtime/io/json_nesting.h"
#include "runtime/io/regular_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace sinew::editor {
namespace {

using Json = nlohmann::json;

// A recipe nests two levels (the object, then clips or pose_space); deeper
// documents are refused before nlohmann's parser and destructor walk them.
constexpr std::size_t kMaxRecipeNesting = 16;

// A value as an error message shows it: scalars as written, cut short;
// arrays and objects by their size. Serialising a container whole would
// copy the file into the message (and recurse through all its levels).
std::string cut(std::string_view text) {
  return text.size() <= 60 ? std::string(text) : std::string(text.substr(0, 60)) + "...";
}

std::string shown(const Json& value) {
  if (value.is_array()) return "an array of " + std::to_string(value.size()) + " values";
  if (value.is_object()) return "an object of " + std::to_string(value.size()) + " fields";
  return cut(value.dump(-1, ' ', false, Json::error_handler_t::replace));
}

Status bad(const std::string& source, std::string_view field, const Json& value, std::string_view detail) {
  return make_error(ErrorCode::kInvalidData, source, field, shown(value), detail);
}

}  // namespace

Expected<SceneRecipe> parse_scene_recipe(std::string_view text, const std::string& source) {
  SINEW_RETURN_IF_ERROR(check_json_nesting(text, kMaxRecipeNesting, source, "(top level)"));
  const Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false, /*ignore_comments=*/true);
  if (j.is_discarded()) return make_error(ErrorCode::kInvalidData, source, "", "", "not valid JSON");
  if (!j.is_object()) return bad(source, "(top level)", j, "expected an object");
  SceneRecipe r;
  r.source = source;
  for (const auto& [key, value] : j.items()) {
    if (key != "model" && key != "clips" && key != "pose_space" && key != "description") {
      return bad(source, cut(key), value, "unknown field (expected model, clips, pose_space, description)");
    }
  }
  if (j.contains("model")) {
    const Json& m = j["model"];
    if (!m.is_string() || m.get<std::string>().empty()) return bad(source, "model", m, "expected a file path");
    // Relative to the recipe, so a recipe works from any working folder.
    const std::filesystem::path model(m.get<std::string>());
    r.model_path = model.is_absolute() ? model.string()
                                       : (std::filesystem::path(source).parent_path() / model).lexically_normal().string();
  }
  if (!j.contains("clips")) return make_error(ErrorCode::kInvalidData, source, "clips", "", "missing: the clips the scene plays");
  const Json& clips = j["clips"];
  if (!clips.is_array() || clips.empty()) return bad(source, "clips", clips, "expected a non-empty array of clip names");
  for (std::size_t i = 0; i < clips.size(); ++i) {
    const std::string field = "clips[" + std::to_string(i) + "]";
    if (!clips[i].is_string() || clips[i].get<std::string>().empty()) {
      return bad(source, field, clips[i], "expected a clip name");
    }
    const std::string name = clips[i].get<std::string>();
    if (std::find(r.clips.begin(), r.clips.end(), name) != r.clips.end()) {
      return make_error(ErrorCode::kDuplicate, source, field, cut(name), "listed twice");
    }
    r.clips.push_back(name);
  }
  if (j.contains("pose_space")) {
    const Json& p = j["pose_space"];
    if (!p.is_object()) return bad(source, "pose_space", p, "expected an object");
    for (const auto& [key, value] : p.items()) {
      const std::string field = "pose_space." + cut(key);
      if (key == "samples") {
        if (!value.is_number_integer() || value.get<long long>() < 0 || value.get<long long>() > 10'000'000) {
          return bad(source, field, value, "expected an integer from 0 to 10000000");
        }
        r.samples = value.get<int>();
      } else if (key == "every_frame_30hz") {
        if (!value.is_boolean()) return bad(source, field, value, "expected true or false");
        r.every_frame_30hz = value.get<bool>();
      } else if (key == "padding") {
        if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0.0 ||
            value.get<double>() > 1.0) {
          return bad(source, field, value, "expected a number from 0 to 1");
        }
        r.padding = value.get<float>();
      } else {
        return bad(source, field, value, "unknown field (expected samples, every_frame_30hz, padding)");
      }
    }
  }
  return r;
}

Expected<SceneRecipe> load_scene_recipe(const std::string& path) {
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIoError, path, "", "", "cannot open the scene recipe");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene_recipe(text.str(), path);
}

Expected<character::Model> keep_recipe_clips(const character::Model& model, const SceneRecipe& recipe) {
  character::Model kept;
  kept.source = model.source;
  kept.skeleton = model.skeleton;
  kept.mesh = model.mesh;
  kept.material_names = model.material_names;
  for (std::size_t i = 0; i < recipe.clips.size(); ++i) {
    const anim::Clip* clip = model.find_clip(recipe.clips[i]);
    if (clip == nullptr) {
      // The first few names: a model may have any number of clips.
      std::string names;
      for (std::size_t c = 0; c < model.clips.size() && c < 5; ++c) {
        names += (c == 0 ? "" : ", ") + cut(model.clips[c].name());
      }
      if (model.clips.size() > 5) names += ", ... " + std::to_string(model.clips.size()) + " in all";
      return make_error(ErrorCode::kNotFound, recipe.source, "clips[" + std::to_string(i) + "]", cut(recipe.clips[i]),
                        "the model has no such clip (it has: " + names + ")");
    }
    kept.clips.push_back(*clip);
  }
  return kept;
}

}  // namespace sinew::editor
