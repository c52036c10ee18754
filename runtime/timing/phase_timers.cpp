#include "runtime/timing/phase_timers.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace sinew {

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

void PhaseTimers::record(std::string_view phase, double milliseconds) {
  for (Phase& p : phases_) {
    if (p.name == phase) {
      p.samples_ms.push_back(milliseconds);
      return;
    }
  }
  phases_.push_back(Phase{std::string(phase), {milliseconds}});
}

std::vector<PhaseSummary> PhaseTimers::summarize() const {
  std::vector<PhaseSummary> out;
  out.reserve(phases_.size());
  for (const Phase& p : phases_) {
    PhaseSummary s;
    s.name = p.name;
    s.samples = p.samples_ms.size();
    if (!p.samples_ms.empty()) {
      s.median_ms = median_of(p.samples_ms);
      const auto [lo, hi] = std::minmax_element(p.samples_ms.begin(), p.samples_ms.end());
      s.min_ms = *lo;
      s.max_ms = *hi;
      s.mean_ms = std::accumulate(p.samples_ms.begin(), p.samples_ms.end(), 0.0) /
                  static_cast<double>(p.samples_ms.size());
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<std::pair<std::string, double>> PhaseTimers::latest() const {
  std::vector<std::pair<std::string, double>> row;
  row.reserve(phases_.size());
  for (const Phase& p : phases_) row.emplace_back(p.name, p.samples_ms.empty() ? 0.0 : p.samples_ms.back());
  return row;
}

double PhaseTimers::median_total_ms() const {
  double total = 0.0;
  for (const PhaseSummary& s : summarize()) total += s.median_ms;
  return total;
}

std::string PhaseTimers::table() const {
  std::string out;
  char line[160];
  std::snprintf(line, sizeof line, "%-20s %8s %11s %11s %11s\n", "phase", "samples", "median ms",
                "min ms", "max ms");
  out += line;
  for (const PhaseSummary& s : summarize()) {
    std::snprintf(line, sizeof line, "%-20s %8zu %11.3f %11.3f %11.3f\n", s.name.c_str(),
                  s.samples, s.median_ms, s.min_ms, s.max_ms);
    out += line;
  }
  return out;
}

std::string PhaseTimers::json() const {
  // Through nlohmann::json: any phase name (quotes, control characters,
  // bytes that are not UTF-8) still makes a valid document.
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const PhaseSummary& s : summarize()) {
    out[s.name] = {{"median_ms", s.median_ms}, {"min_ms", s.min_ms}, {"max_ms", s.max_ms}, {"samples", s.samples}};
  }
  return out.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

double ScopedPhase::stop() {
  if (timers_ == nullptr) return 0.0;
  const auto end = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(end - start_).count();
  timers_->record(phase_, ms);
  timers_ = nullptr;
  return ms;
}

}  // namespace sinew
