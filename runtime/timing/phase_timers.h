// PhaseTimers: per-phase wall-clock samples so every program can print
// medians (docs/DESIGN.md section 6: animation, skinning, boxes, top-level build,
// trace, shade, display). One sample per phase per frame; a phase's name is
// registered on first use and keeps its first-use order in reports.
//
// Not thread-safe: phases are timed around parallel work by the thread that
// launches it, never from inside jobs.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sinew {

struct PhaseSummary {
  std::string name;
  std::size_t samples = 0;
  double median_ms = 0.0;
  double min_ms = 0.0;
  double max_ms = 0.0;
  double mean_ms = 0.0;
};

class PhaseTimers {
 public:
  void record(std::string_view phase, double milliseconds);

  std::vector<PhaseSummary> summarize() const;
  // Sum over phases of their medians: a robust "typical frame" time.
  double median_total_ms() const;

  // A fixed-width table: phase, samples, median, min, max.
  std::string table() const;
  // {"phase": {"median_ms": .., "min_ms": .., "max_ms": .., "samples": ..}, ...}
  std::string json() const;

  // The phases in first-use order and each one's latest sample (0 for a
  // phase not recorded yet): one frame's row for per-frame logs.
  std::vector<std::pair<std::string, double>> latest() const;

  void clear() { phases_.clear(); }

 private:
  struct Phase {
    std::string name;
    std::vector<double> samples_ms;
  };
  std::vector<Phase> phases_;
};

// Records the time from construction to destruction (or stop()) into a phase.
class ScopedPhase {
 public:
  ScopedPhase(PhaseTimers& timers, std::string_view phase)
      : timers_(&timers), phase_(phase), start_(std::chrono::steady_clock::now()) {}
  ~ScopedPhase() { stop(); }
  ScopedPhase(const ScopedPhase&) = delete;
  ScopedPhase& operator=(const ScopedPhase&) = delete;

  double stop();  // returns milliseconds; later calls do nothing

 private:
  PhaseTimers* timers_;
  std::string_view phase_;
  std::chrono::steady_clock::time_point start_;
};

// Median of a sample set (mean of the two middle values for an even count);
// 0 for an empty set.
double median_of(std::vector<double> values);

}  // namespace sinew
