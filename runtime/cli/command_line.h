// One command-line convention for every Sinew program, on CLI11:
// `--flag value` and `--flag=value` alike, generated `--help`, and usage
// errors as a Status naming the flag and the offending value, which the
// program's main turns into one line on stderr and exit code 2.
//
// Options are declared with a name, the form of their value and a help
// line; the parser collects their text, and the typed converters of
// option_values.h validate it, so every message keeps Sinew's
// "--size = 0x5: expected WxH ..." form. Parsing never prints nor exits.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "runtime/core/expected.h"

namespace CLI {
class App;
}

namespace sinew::cli {

class UsageFirstFormatter;

enum class ParseResult {
  kRun,   // go on with the options
  kHelp,  // --help or -h was given: print help() and exit 0
};

class CommandLine {
 public:
  // `program` as typed ("sinew-editor render"): the usage line and every
  // message start with it. `description`: the paragraph after the usage line.
  CommandLine(std::string program, std::string description);
  ~CommandLine();
  CommandLine(const CommandLine&) = delete;
  CommandLine& operator=(const CommandLine&) = delete;

  // A value-taking option ("--size" or "-o,--out"); `value_form` names its
  // value in the help ("WxH"). The reference holds its text once parsed
  // (empty when not given) and lives as long as this object.
  const std::optional<std::string>& option(const std::string& names, const std::string& value_form,
                                           const std::string& help);
  // A value-taking option that may be given several times ("--light"):
  // its texts in the order given (empty when not given).
  const std::vector<std::string>& repeated_option(const std::string& names, const std::string& value_form,
                                                  const std::string& help);
  // A switch: true when given.
  const bool& flag(const std::string& names, const std::string& help);
  // The positional arguments, in order; more than `max` is a usage error.
  // Declared once per command line.
  const std::vector<std::string>& positionals(const std::string& name, const std::string& help, std::size_t max);
  // A command of a tool of several ("sinew-editor bake ..."): the first
  // positional argument picks it; everything after it is left, unparsed,
  // to command_arguments().
  void command(const std::string& name, const std::string& help);
  // Paragraphs printed after the options.
  void footer(const std::string& text);

  // Errors name the flag and the value: an unknown option, a missing value,
  // a flag given twice, too many positionals, an unknown command.
  Expected<ParseResult> parse(const std::vector<std::string>& args);

  // After parse(), for a tool of several commands: the command chosen
  // (empty: none was given) and its arguments.
  const std::string& chosen_command() const { return chosen_command_; }
  const std::vector<std::string>& command_arguments() const { return command_arguments_; }

  const std::string& program() const { return program_; }
  std::string help() const;

 private:
  std::string program_;
  std::unique_ptr<CLI::App> app_;
  std::shared_ptr<UsageFirstFormatter> formatter_;
  // Deques: CLI11 keeps references to them while more are declared.
  std::deque<std::optional<std::string>> texts_;
  std::deque<bool> switches_;
  std::deque<std::vector<std::string>> lists_;
  std::vector<std::string> positionals_;
  std::size_t max_positionals_ = 0;
  std::vector<std::string> commands_;
  std::string chosen_command_;
  std::vector<std::string> command_arguments_;
};

// What a main does with a parse or a later validation: help on `out` (exit
// 0), or the error as one line "PROGRAM: MESSAGE" on `err` (exit 2); nothing
// when the program goes on.
std::optional<int> help_or_usage_error(const CommandLine& line, const Expected<ParseResult>& parsed,
                                       std::ostream& out, std::ostream& err);
// A usage error found after parsing (a bad value): one line, exit code 2.
int usage_error(const std::string& program, const Status& status, std::ostream& err);

}  // namespace sinew::cli
