// Scene recipes: parsing with errors that name the field, and keeping only
// the clips a scene plays.
#include <gtest/gtest.h>

#include "content/mannequin/mannequin.h"
#include "editor/scene/scene_recipe.h"

namespace sinew::editor {
namespace {

TEST(SceneRecipe, ParsesTheFieldsAndResolvesTheModelAgainstTheRecipe) {
  auto r = parse_scene_recipe(R"({
      "description": "two clips",
      "model": "../models/hero.glb",
      "clips": ["walk", "wave"],
      "pose_space": {"samples": 12, "every_frame_30hz": false, "padding": 0.02}
    })",
                              "/data/scenes/crowd.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->model_path, "/data/models/hero.glb");
  EXPECT_EQ(r->clips, (std::vector<std::string>{"walk", "wave"}));
  EXPECT_EQ(r->samples, 12);
  EXPECT_FALSE(r->every_frame_30hz);
  EXPECT_FLOAT_EQ(r->padding, 0.02f);
  // Defaults: every key time, plus 30 Hz, no padding; no model (given on the command line).
  auto minimal = parse_scene_recipe(R"({"clips": ["idle"]})", "s.json");
  ASSERT_TRUE(minimal.ok());
  EXPECT_TRUE(minimal->model_path.empty());
  EXPECT_EQ(minimal->samples, 0);
  EXPECT_TRUE(minimal->every_frame_30hz);
}

TEST(SceneRecipe, BadRecipesNameTheFieldAndValue) {
  struct Case {
    const char* json;
    const char* field;
  };
  const Case cases[] = {
      {R"({"clips": []})", "clips"},
      {R"({"model": "m.glb"})", "clips"},
      {R"({"clips": ["walk", 7]})", "clips[1]"},
      {R"({"clips": ["walk", "walk"]})", "clips[1]"},
      {R"({"clips": ["walk"], "pose_space": {"samples": -1}})", "pose_space.samples"},
      {R"({"clips": ["walk"], "pose_space": {"padding": 3}})", "pose_space.padding"},
      {R"({"clips": ["walk"], "pose_space": {"mode": "arbitrary"}})", "pose_space.mode"},
      {R"({"clips": ["walk"], "camera": 1})", "camera"},
      {R"({"model": 5, "clips": ["walk"]})", "model"},
  };
  for (const Case& c : cases) {
    auto r = parse_scene_recipe(c.json, "bad.json");
    ASSERT_FALSE(r.ok()) << c.json;
    EXPECT_EQ(r.status().file(), "bad.json");
    EXPECT_EQ(r.status().field(), c.field) << c.json << " -> " << r.status().message();
  }
  auto broken = parse_scene_recipe("{\"clips\": [", "broken.json");
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.status().message().find("not valid JSON"), std::string::npos);
  EXPECT_EQ(load_scene_recipe("/nonexistent/scene.json").status().code(), ErrorCode::kNotFound);
}

// A recipe nested 100,000 levels deep crashed while its error message was
// built (the value was serialised whole). Nesting is bounded before parsing,
// and no message carries more of the input than a short excerpt.
TEST(SceneRecipe, DeepNestingAndHugeValuesGiveShortMessages) {
  for (const std::size_t depth : {std::size_t{17}, std::size_t{100000}}) {
    const std::string deep = std::string(depth, '[') + std::string(depth, ']');
    for (const std::string& json : {R"({"clips": )" + deep + "}", R"({"clips": ["walk"], "camera": )" + deep + "}"}) {
      auto r = parse_scene_recipe(json, "deep.json");
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.status().code(), ErrorCode::kLimitExceeded) << r.status().message();
      EXPECT_EQ(r.status().file(), "deep.json");
      EXPECT_LE(r.status().message().size(), 300u);
    }
  }
  const std::string huge(1 << 20, 'x');
  const std::string within = std::string(15, '[') + "\"" + huge + "\"" + std::string(15, ']');
  const std::string cases[] = {
      R"({"clips": )" + within + "}",
      R"({"clips": ["walk"], "camera": )" + within + "}",
      R"({"clips": [")" + huge + R"(", ")" + huge + R"("]})",
      R"({"clips": ["walk"], ")" + huge + R"(": 1})",
      R"({"clips": ["walk"], "pose_space": {")" + huge + R"(": 1}})",
      R"({"clips": ["walk"], "model": 1e308, "pose_space": {"samples": ")" + huge + R"("}})",
  };
  for (const std::string& json : cases) {
    auto r = parse_scene_recipe(json, "huge.json");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().file(), "huge.json");
    EXPECT_LE(r.status().message().size(), 300u) << r.status().message().substr(0, 400);
  }
}

TEST(SceneRecipe, KeepsOnlyTheRecipesClipsInItsOrder) {
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  ASSERT_GE(model->clips.size(), 3u);
  SceneRecipe recipe;
  recipe.source = "s.json";
  recipe.clips = {model->clips[2].name(), model->clips[0].name()};
  auto kept = keep_recipe_clips(*model, recipe);
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  ASSERT_EQ(kept->clips.size(), 2u);
  EXPECT_EQ(kept->clips[0].name(), model->clips[2].name());
  EXPECT_EQ(kept->clips[1].name(), model->clips[0].name());
  EXPECT_EQ(kept->mesh.triangles, model->mesh.triangles);
  recipe.clips = {"moonwalk"};
  auto missing = keep_recipe_clips(*model, recipe);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().field(), "clips[0]");
  EXPECT_NE(missing.status().message().find(model->clips[0].name()), std::string::npos);  // lists what there is
}

}  // namespace
}  // namespace sinew::editor
