#include "tests/bench/bench_options.h"

#include <cstdlib>

#include "runtime/cli/option_values.h"
#include "runtime/jobs/job_system.h"

namespace sinew::bench {

BenchFlag threads_flag(const std::string& defaults) {
  return {"--threads", "N", "worker threads, 0 = all cores (default " + defaults + ")"};
}
BenchFlag thread_list_flag(const std::string& defaults) {
  return {"--threads", "LIST", "thread counts, e.g. 1,2; 0 = all cores (default " + defaults + ")"};
}
BenchFlag size_flag(const std::string& defaults) { return {"--size", "WxH", "image size (default " + defaults + ")"}; }
BenchFlag frames_flag(const std::string& help) { return {"--frames", "N", help}; }
BenchFlag models_flag(const std::string& help) { return {"--models", "LIST", help}; }
BenchFlag quick_flag(const std::string& what) { return {"--quick", "", what + " (later flags override)"}; }
BenchFlag shared_flag() { return {"--shared", "DIR", "the shared folder holding content/cal3d/cally"}; }
BenchFlag json_flag() { return {"--json", "FILE", "also write the numbers as JSON"}; }
BenchFlag markdown_flag() { return {"--markdown", "FILE", "also write the tables as a Markdown section"}; }

BenchArgs::BenchArgs(const std::string& bench, const std::string& description, const std::vector<BenchFlag>& flags)
    : line_("sinew-bench " + bench, description) {
  for (const BenchFlag& flag : flags) {
    if (flag.value_form.empty()) {
      switches_.emplace_back(flag.name, &line_.flag(flag.name, flag.help));
    } else {
      values_.emplace_back(flag.name, &line_.option(flag.name, flag.value_form, flag.help));
    }
  }
}

Expected<cli::ParseResult> BenchArgs::parse(const std::vector<std::string>& args) { return line_.parse(args); }

std::optional<std::string> BenchArgs::value(std::string_view name) const {
  for (const auto& [declared, text] : values_) {
    if (declared == name) return *text;
  }
  std::abort();  // a benchmark reads an option it did not declare
}

bool BenchArgs::has(std::string_view name) const {
  for (const auto& [declared, given] : switches_) {
    if (declared == name) return *given;
  }
  for (const auto& [declared, text] : values_) {
    if (declared == name) return text->has_value();
  }
  std::abort();  // a benchmark reads an option it did not declare
}

Status BenchArgs::read(std::string_view name, std::int64_t lo, std::int64_t hi, int& out) const {
  if (const auto text = value(name)) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int(name, *text, lo, hi));
    out = static_cast<int>(n);
  }
  return {};
}

Status BenchArgs::read(std::string_view name, double lo, double hi, float& out) const {
  if (const auto text = value(name)) {
    SINEW_ASSIGN_OR_RETURN(const double x, cli::parse_double(name, *text, lo, hi));
    out = static_cast<float>(x);
  }
  return {};
}

Status BenchArgs::read(std::string_view name, int lo, int hi, std::vector<int>& out) const {
  if (const auto text = value(name)) {
    SINEW_ASSIGN_OR_RETURN(out, cli::parse_int_list(name, *text, lo, hi));
  }
  return {};
}

Status BenchArgs::read(std::string_view name, bool& out) const {
  if (const auto text = value(name)) {
    SINEW_ASSIGN_OR_RETURN(out, cli::parse_on_off(name, *text));
  }
  return {};
}

Status BenchArgs::read(std::string_view name, std::string& out) const {
  if (const auto text = value(name)) out = *text;
  return {};
}

Status BenchArgs::read_size(int max_side, int& width, int& height) const {
  if (const auto text = value("--size")) {
    SINEW_ASSIGN_OR_RETURN(const cli::Size2 size, cli::parse_size("--size", *text, max_side));
    width = size.width;
    height = size.height;
  }
  return {};
}

Status BenchArgs::read_threads(int& out) const {
  if (const auto text = value("--threads")) {
    SINEW_ASSIGN_OR_RETURN(out, parse_thread_count("--threads", *text));
  }
  return {};
}

Status BenchArgs::read_threads(std::vector<int>& out) const {
  if (const auto text = value("--threads")) {
    SINEW_ASSIGN_OR_RETURN(out, parse_thread_counts("--threads", *text));
  }
  return {};
}

Status BenchArgs::read_models(std::vector<std::string>& out) const {
  if (const auto text = value("--models")) {
    SINEW_ASSIGN_OR_RETURN(out, cli::parse_list("--models", *text));
    for (const std::string& name : out) {
      if (name != "cally" && name != "mannequin") {
        return invalid_argument("--models", name, "unknown model (expected cally or mannequin)");
      }
    }
  }
  return {};
}

Expected<int> parse_thread_count(std::string_view flag, const std::string& text) {
  SINEW_ASSIGN_OR_RETURN(const int threads, cli::parse_threads(flag, text));
  return threads == 0 ? JobSystem::hardware_threads() : threads;
}

Expected<std::vector<int>> parse_thread_counts(std::string_view flag, const std::string& text) {
  SINEW_ASSIGN_OR_RETURN(std::vector<int> counts, cli::parse_int_list(flag, text, 0, cli::kMaxThreads));
  for (int& threads : counts) {
    if (threads == 0) threads = JobSystem::hardware_threads();
  }
  return counts;
}

}  // namespace sinew::bench
