// Small pieces the sinew-bench programs share: the machine and the date for
// their header lines, and the models they measure.
#pragma once

#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "content/mannequin/mannequin.h"
#include "editor/cli/cli_args.h"
#include "editor/import/cal3d_importer.h"
#include "runtime/core/expected.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/jobs/job_system.h"

namespace sinew::bench {

// The CPU's model name from /proc/cpuinfo, "unknown" elsewhere.
inline std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) break;
    const std::size_t start = line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? std::string() : line.substr(start);
  }
  return "unknown";
}

inline std::string utc_date() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

// The lines every benchmark table starts with: what ran, where, when.
inline void print_bench_header(const char* name, const std::string& command_line, const std::string& threads,
                               const std::string& cpu, const std::string& date) {
  std::printf("sinew-bench %s\n", name);
  std::printf("  command: %s\n", command_line.c_str());
  std::printf("  cpu:     %s (%d hardware threads)\n", cpu.c_str(), JobSystem::hardware_threads());
  std::printf("  threads: %s\n", threads.c_str());
  std::printf("  isa:     %s\n", std::string(build_isa()).c_str());
  std::printf("  date:    %s\n", date.c_str());
}

// A comma-separated list of integers in [lo, hi] ("1,6,12").
inline Expected<std::vector<int>> parse_int_list(std::string_view flag, const std::string& text, int lo, int hi) {
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::string> items, editor::cli::parse_list(flag, text));
  std::vector<int> values;
  for (const std::string& item : items) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, editor::cli::parse_int(flag, item, lo, hi));
    values.push_back(static_cast<int>(n));
  }
  return values;
}

// "mannequin" (procedural) or "cally" (from SHARED/content/cal3d/cally).
// Cally is optional content: a missing file is a note, not a failure, so a
// benchmark still runs on a machine with only the procedural mannequin.
inline Expected<std::optional<editor::ImportedModel>> load_model(const std::string& name, const std::string& shared,
                                                          std::string& note) {
  if (name == "mannequin") {
    SINEW_ASSIGN_OR_RETURN(editor::ImportedModel model, content::make_mannequin());
    return std::optional<editor::ImportedModel>(std::move(model));
  }
  const std::string cfg = shared + "/content/cal3d/cally/cally.cfg";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(cfg, ec)) {
    note = "cally skipped: " + cfg + " not found (pass --shared DIR)";
    return std::optional<editor::ImportedModel>();
  }
  SINEW_ASSIGN_OR_RETURN(editor::ImportedModel model, editor::import_cal3d(cfg));
  return std::optional<editor::ImportedModel>(std::move(model));
}

// The index of the clip named "walk".
inline Expected<std::size_t> find_walk_clip(const editor::ImportedModel& model, const std::string& name) {
  for (std::size_t i = 0; i < model.clips.size(); ++i) {
    if (model.clips[i].name() == "walk") return i;
  }
  return make_error(ErrorCode::kNotFound, name, "clip", "walk", "the model has no walk clip");
}

}  // namespace sinew::bench
