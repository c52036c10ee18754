// The headless demo's timings.json: every frame's phase times, then a
// summary (per-phase medians, fps, the model and the run's settings). Built
// with nlohmann::json, so any model path (quotes, backslashes, control
// characters, any UTF-8) gives a valid document.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "runtime/timing/phase_timers.h"

namespace sinew::demo {

struct TimingsRun {
  std::vector<std::vector<std::pair<std::string, double>>> frames;  // per frame: (phase, ms)
  const PhaseTimers* timers = nullptr;                              // for the medians
  std::string model;
  std::size_t triangles = 0;
  std::uint32_t pose_samples = 0;
  int characters = 0;
  int width = 0;
  int height = 0;
  int threads = 0;
  std::uint64_t escaped_triangles = 0;
};

// The document, indented, ending in a newline. Non-finite times are written
// as 0 (JSON has no infinity).
std::string timings_json(const TimingsRun& run);

}  // namespace sinew::demo
