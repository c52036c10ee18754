// A small command-line parser shared by sinew-editor's subcommands.
//
// Parsing never exits and never prints: every function returns the value or
// a Status whose field is the flag and whose value is the offending text
// ("--size = 0x5: expected WxH ..."), and the caller decides what to do
// (sinew-editor: exit code 2 for usage errors). Flags are declared up front
// so an unknown option or a value-taking flag without its value is caught
// before anything runs; `--flag value` and `--flag=value` are both accepted.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "editor/import/gltf_importer.h"
#include "runtime/core/expected.h"

namespace sinew::editor::cli {

struct FlagSpec {
  std::string name;          // with the dashes: "--size"
  bool takes_value = true;   // false: a switch such as --help
};

struct ParsedArgs {
  std::vector<std::string> positionals;
  // In command-line order; a flag given twice is an error, so each name
  // appears at most once.
  std::vector<std::pair<std::string, std::string>> flags;

  bool has(std::string_view name) const;
  // The flag's value, or nothing when it was not given.
  std::optional<std::string> value(std::string_view name) const;
};

// Splits `args` into positionals and declared flags. A lone "-" and
// anything not starting with "--" (or "-h") is a positional; "--" ends the
// flags. Errors: an undeclared flag, a missing value, a value given to a
// switch, a flag repeated.
Expected<ParsedArgs> parse_args(const std::vector<std::string>& args, const std::vector<FlagSpec>& specs);

// Typed conversions of one flag's text. `flag` names the flag in errors.
Expected<std::int64_t> parse_int(std::string_view flag, const std::string& text, std::int64_t lo,
                                 std::int64_t hi);
Expected<std::uint64_t> parse_uint64(std::string_view flag, const std::string& text);
// A finite decimal number in [lo, hi].
Expected<double> parse_double(std::string_view flag, const std::string& text, double lo, double hi);
// "a,b,c": exactly `count` finite floats.
Expected<std::vector<float>> parse_floats(std::string_view flag, const std::string& text, std::size_t count);
// "a,b,c": a comma-separated list of non-empty names.
Expected<std::vector<std::string>> parse_list(std::string_view flag, const std::string& text);

struct Size2 {
  int width = 0;
  int height = 0;
};
// "WxH" with both in [1, max_side].
Expected<Size2> parse_size(std::string_view flag, const std::string& text, int max_side);

// One of `choices`; returns its index.
Expected<int> parse_choice(std::string_view flag, const std::string& text,
                           std::initializer_list<std::string_view> choices);
// "on" or "off".
Expected<bool> parse_on_off(std::string_view flag, const std::string& text);
// --max-triangles, --max-clips, --max-keys, --max-nodes and --max-bytes into
// `limits` (each at least 1).
Status parse_import_limits(const ParsedArgs& args, ImportLimits& limits);
// Their help lines.
std::string import_limits_usage();
// Folders separated by ':', each existing.
Expected<std::vector<std::string>> parse_folder_list(std::string_view flag, const std::string& text);

}  // namespace sinew::editor::cli
