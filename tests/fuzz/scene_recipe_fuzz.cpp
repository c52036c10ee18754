// libFuzzer target for scene recipes (editor/scene/scene_recipe.h).
//
// Each input is the recipe's JSON text, parsed as "scenes/fuzz.json" (no
// file is read). When it parses, its clips are looked up in a fixed model:
// the procedural mannequin, whose clips are idle, walk, run and wave, so
// recipes naming those succeed and others are refused. A finding: any sanitizer
// report, leak, trap, time-out or OOM; a refusal without a code or message;
// an accepted recipe breaking the header's promises (clips non-empty and
// unique, samples >= 0, padding finite); or keep_recipe_clips returning
// other clips than the ones the recipe names (by name or '#index'), in
// another order.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "content/mannequin/mannequin.h"
#include "editor/scene/scene_recipe.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace sinew;

const character::Model& mannequin() {
  static const character::Model model = [] {
    auto made = content::make_mannequin();
    fuzz::require(made.ok());
    return *made;
  }();
  return model;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  auto recipe = editor::parse_scene_recipe(json, "scenes/fuzz.json");
  if (!recipe.ok()) {
    fuzz::require_clear_error(recipe.status());
    return 0;
  }
  fuzz::require(!recipe->clips.empty());
  fuzz::require(std::set<std::string>(recipe->clips.begin(), recipe->clips.end()).size() ==
                recipe->clips.size());
  fuzz::require(recipe->samples >= 0);
  fuzz::require(std::isfinite(recipe->padding));

  auto kept = editor::keep_recipe_clips(mannequin(), *recipe);
  if (!kept.ok()) {
    fuzz::require_clear_error(kept.status());
    return 0;
  }
  fuzz::require(kept->clips.size() == recipe->clips.size());
  for (std::size_t i = 0; i < kept->clips.size(); ++i) {
    // A recipe may name a clip by index ("#2"): compare with the lookup.
    const anim::Clip* wanted = mannequin().find_clip(recipe->clips[i]);
    fuzz::require(wanted != nullptr && kept->clips[i].name() == wanted->name());
  }
  return 0;
}
