#include "game_demo/timings_json.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace sinew::demo {
namespace {

double finite_or_zero(double v) { return std::isfinite(v) ? v : 0.0; }

}  // namespace

std::string timings_json(const TimingsRun& run) {
  nlohmann::ordered_json doc;
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (std::size_t f = 0; f < run.frames.size(); ++f) {
    nlohmann::ordered_json row;
    row["frame"] = f;
    for (const auto& [phase, ms] : run.frames[f]) row[phase] = finite_or_zero(ms);
    frames.push_back(std::move(row));
  }
  doc["frames"] = std::move(frames);
  const double total = run.timers != nullptr ? run.timers->median_total_ms() : 0.0;
  nlohmann::ordered_json summary;
  summary["fps"] = total > 0.0 ? finite_or_zero(1000.0 / total) : 0.0;
  summary["frame_median_ms"] = finite_or_zero(total);
  summary["threads"] = run.threads;
  summary["characters"] = run.characters;
  summary["size"] = {run.width, run.height};
  summary["model"] = run.model;
  summary["triangles"] = run.triangles;
  summary["pose_samples"] = run.pose_samples;
  summary["escaped_triangles"] = run.escaped_triangles;
  nlohmann::ordered_json phases = nlohmann::ordered_json::object();
  if (run.timers != nullptr) {
    for (const PhaseSummary& s : run.timers->summarize()) {
      phases[s.name] = {{"median_ms", finite_or_zero(s.median_ms)},
                        {"min_ms", finite_or_zero(s.min_ms)},
                        {"max_ms", finite_or_zero(s.max_ms)},
                        {"samples", s.samples}};
    }
  }
  summary["phases"] = std::move(phases);
  doc["summary"] = std::move(summary);
  // Invalid UTF-8 in a path is replaced rather than thrown on.
  return doc.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace sinew::demo
