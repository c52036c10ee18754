#include "game_demo/character_cost.h"

#include <algorithm>
#include <array>
#include <string_view>

namespace sinew::demo {
namespace {

// The phases that grow with the characters rather than with the pixels:
// the world's step and the scene's per-frame preparation.
constexpr std::array<std::string_view, 5> kUpdatePhases = {"animation", "skinning", "boxes", "fallback",
                                                           "top level"};
constexpr std::array<std::string_view, 3> kTracePhases = {"trace primary", "trace shadow", "trace ao"};

template <std::size_t N>
bool listed(const std::array<std::string_view, N>& names, std::string_view name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

CharacterCost per_character_cost(std::span<const std::pair<std::string, double>> phases_ms, int characters) {
  CharacterCost cost;
  if (characters <= 0) return cost;
  for (const auto& [name, ms] : phases_ms) {
    if (listed(kUpdatePhases, name)) cost.update_ms += ms;
    if (listed(kTracePhases, name)) cost.trace_ms += ms;
  }
  cost.update_ms /= characters;
  cost.trace_ms /= characters;
  return cost;
}

}  // namespace sinew::demo
