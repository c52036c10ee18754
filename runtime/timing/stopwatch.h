// Milliseconds since a steady-clock time point: the one helper behind every
// timed phase (pass and bake statistics, the demo, the benchmarks).
#pragma once

#include <chrono>

namespace sinew {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace sinew
