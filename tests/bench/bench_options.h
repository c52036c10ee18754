// The benchmarks' command lines (CLI11, through runtime/cli): each benchmark
// lists its options as a table, and the options several benchmarks share
// are declared here once, with one spelling, value form and help line, and
// one reading of their values (--threads 0 = every core, as everywhere).
#pragma once

#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "runtime/cli/command_line.h"
#include "runtime/core/expected.h"

namespace sinew::bench {

struct BenchFlag {
  std::string name;        // "--size"
  std::string value_form;  // "WxH"; empty: a switch
  std::string help;
};

// The shared options. `defaults` completes the help line ("1,2").
BenchFlag threads_flag(const std::string& defaults);       // --threads N
BenchFlag thread_list_flag(const std::string& defaults);   // --threads LIST
BenchFlag size_flag(const std::string& defaults);          // --size WxH
BenchFlag frames_flag(const std::string& help);            // --frames N
BenchFlag models_flag(const std::string& help);            // --models LIST
BenchFlag quick_flag(const std::string& what);             // --quick
BenchFlag shared_flag();                                   // --shared DIR
BenchFlag json_flag();                                     // --json FILE
BenchFlag markdown_flag();                                 // --markdown FILE

// One benchmark's command line: "sinew-bench NAME [options]", no positionals.
class BenchArgs {
 public:
  BenchArgs(const std::string& bench, const std::string& description, const std::vector<BenchFlag>& flags);

  Expected<cli::ParseResult> parse(const std::vector<std::string>& args);
  // The text of a declared option, when given (an undeclared name is a bug:
  // it aborts, so a typo cannot silently read as "not given").
  std::optional<std::string> value(std::string_view name) const;
  bool has(std::string_view name) const;

  // Typed reads of a declared option: `out` takes the value when the option
  // was given and keeps its default otherwise; errors name the option and
  // the text ("--frames = 0: ...").
  Status read(std::string_view name, std::int64_t lo, std::int64_t hi, int& out) const;  // an integer
  Status read(std::string_view name, int lo, int hi, std::vector<int>& out) const;       // "1,4,16"
  Status read(std::string_view name, bool& out) const;                                 // on|off
  Status read(std::string_view name, double lo, double hi, float& out) const;          // a number
  Status read(std::string_view name, std::string& out) const;                          // text
  Status read_size(int max_side, int& width, int& height) const;                       // --size WxH
  Status read_threads(int& out) const;                                                 // --threads N
  Status read_threads(std::vector<int>& out) const;                                    // --threads LIST
  Status read_models(std::vector<std::string>& out) const;                             // --models cally,mannequin

  const cli::CommandLine& line() const { return line_; }

 private:
  cli::CommandLine line_;
  std::vector<std::pair<std::string, const std::optional<std::string>*>> values_;
  std::vector<std::pair<std::string, const bool*>> switches_;
};

// --threads N and LIST: 0 is every core, given as the count so tables and
// headers print what ran.
Expected<int> parse_thread_count(std::string_view flag, const std::string& text);
Expected<std::vector<int>> parse_thread_counts(std::string_view flag, const std::string& text);

// Parses `args` and reads them into a benchmark's Options with `read`
// (nothing is read when --help was given: Options::help is set instead).
template <class Options>
Expected<Options> parse_bench_options(BenchArgs& bench_args, const std::vector<std::string>& args,
                                      Status (*read)(const BenchArgs&, Options&)) {
  SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, bench_args.parse(args));
  Options o;
  if (result == cli::ParseResult::kHelp) {
    o.help = true;
    return o;
  }
  SINEW_RETURN_IF_ERROR(read(bench_args, o));
  return o;
}

// What every benchmark's entry point does with its parsed options: help on
// stdout (exit 0), a usage error as one line on stderr (exit 2); nothing
// when the run goes on.
template <class Options>
std::optional<int> usage_exit(const BenchArgs& args, const Expected<Options>& parsed) {
  if (!parsed.ok()) return cli::usage_error(args.line().program(), parsed.status(), std::cerr);
  if (parsed->help) {
    std::cout << args.line().help() << std::flush;
    return 0;
  }
  return std::nullopt;
}

}  // namespace sinew::bench
