// The benchmarks' command lines (CLI11, through runtime/cli): each benchmark
// lists its options as a table, and the options several benchmarks share
// are declared here once, with one spelling, value form and help line, and
// one reading of their values (--threads 0 = every core, as everywhere).
#pragma once

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
