// The HUD's and the demo benchmark's cost per character: which phases
// count as update and which as trace, divided by the characters.
#include "game_demo/character_cost.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace sinew::demo {
namespace {

TEST(CharacterCost, SplitsUpdateAndTracePhasesPerCharacter) {
  const std::vector<std::pair<std::string, double>> phases = {
      {"animation", 1.0}, {"skinning", 2.0},     {"boxes", 0.5},        {"fallback", 0.25}, {"top level", 0.25},
      {"trace primary", 6.0}, {"trace shadow", 2.0}, {"trace ao", 4.0}, {"shade", 100.0}, {"display", 100.0}};
  const CharacterCost cost = per_character_cost(phases, 4);
  EXPECT_DOUBLE_EQ(cost.update_ms, 4.0 / 4);  // animation + skinning + boxes + fallback + top level
  EXPECT_DOUBLE_EQ(cost.trace_ms, 12.0 / 4);  // primary + shadow + ambient occlusion; shading and display count in neither
}

TEST(CharacterCost, MissingPhasesCountZero) {
  const std::vector<std::pair<std::string, double>> phases = {{"trace primary", 3.0}};
  const CharacterCost cost = per_character_cost(phases, 3);
  EXPECT_DOUBLE_EQ(cost.update_ms, 0.0);
  EXPECT_DOUBLE_EQ(cost.trace_ms, 1.0);
}

TEST(CharacterCost, NoCharactersCostsNothing) {
  const std::vector<std::pair<std::string, double>> phases = {{"animation", 1.0}, {"trace primary", 3.0}};
  for (const int characters : {0, -1}) {
    const CharacterCost cost = per_character_cost(phases, characters);
    EXPECT_EQ(cost.update_ms, 0.0) << characters;
    EXPECT_EQ(cost.trace_ms, 0.0) << characters;
  }
}

}  // namespace
}  // namespace sinew::demo
