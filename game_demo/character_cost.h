// A frame's cost per character, split the way a crowd grows it: the update
// (animating the characters, then the scene's per-frame preparation:
// skinning, boxes, the fallback and the top level) and the trace (primary,
// shadow and ambient occlusion rays). Each is the frame's time for that part divided by the
// characters in the world, culled ones included: what one more character
// costs on average, shown by the HUD and reported by `sinew-bench demo`.
#pragma once

#include <span>
#include <string>
#include <utility>

namespace sinew::demo {

struct CharacterCost {
  double update_ms = 0.0;  // per character
  double trace_ms = 0.0;   // per character
};

// The phases as the session records them (DemoSession::timers: "animation",
// "skinning", "boxes", "fallback", "top level", "trace primary", "trace
// shadow", "trace ao", ...): the update and trace phases summed, divided by
// `characters`. Other phases (shade, display) count in neither. Zero for
// no characters.
CharacterCost per_character_cost(std::span<const std::pair<std::string, double>> phases_ms, int characters);

}  // namespace sinew::demo
