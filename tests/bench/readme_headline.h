// The README's headline table: Sinew against Embree 3's best mode on the
// report's two Embree scenes. `sinew-bench report` writes it between two
// markers in README.md from the same JSON as docs/BENCHMARKS.md, so the
// front page cannot drift from the report.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace sinew::bench {

inline constexpr const char* kHeadlineBegin = "<!-- headline table: written by sinew-bench report, do not edit -->";
inline constexpr const char* kHeadlineEnd = "<!-- end of headline table -->";

// One row per run (the embree and embree-large sections' JSON; a null or
// unusable run gives no row): its walk-like first clip at the most threads
// measured, Sinew's and the best Embree row's median frame and trace
// times. Empty when no run has a row.
std::string headline_table(const nlohmann::ordered_json* small, const nlohmann::ordered_json* large);

// `text` with everything between the markers replaced by `table`; nullopt
// when the markers are missing or out of order.
std::optional<std::string> replace_headline(const std::string& text, const std::string& table);

}  // namespace sinew::bench
