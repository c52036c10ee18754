// Typed values of command-line options, from the text CommandLine collected.
// Each returns the value or a Status whose field is the flag and whose value
// is the offending text ("--size = 0x5: expected WxH ..."): a usage error.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/expected.h"

namespace sinew::cli {

// `flag` names the flag in errors.
Expected<std::int64_t> parse_int(std::string_view flag, const std::string& text, std::int64_t lo,
                                 std::int64_t hi);
Expected<std::uint64_t> parse_uint64(std::string_view flag, const std::string& text);
// A finite decimal number in [lo, hi].
Expected<double> parse_double(std::string_view flag, const std::string& text, double lo, double hi);
// "a,b,c": exactly `count` finite floats.
Expected<std::vector<float>> parse_floats(std::string_view flag, const std::string& text, std::size_t count);
// "a,b,c": a comma-separated list of non-empty names.
Expected<std::vector<std::string>> parse_list(std::string_view flag, const std::string& text);
// "1,6,12": a comma-separated list of integers in [lo, hi].
Expected<std::vector<int>> parse_int_list(std::string_view flag, const std::string& text, int lo, int hi);

struct Size2 {
  int width = 0;
  int height = 0;
};
// "WxH" with both in [min_side, max_side].
Expected<Size2> parse_size(std::string_view flag, const std::string& text, int max_side, int min_side = 1);

// One of `choices`; returns its index.
Expected<int> parse_choice(std::string_view flag, const std::string& text,
                           std::initializer_list<std::string_view> choices);
// "on" or "off".
Expected<bool> parse_on_off(std::string_view flag, const std::string& text);
// Folders separated by ':', each existing.
Expected<std::vector<std::string>> parse_folder_list(std::string_view flag, const std::string& text);

// A light as typed: "X,Y,Z" or "point:X,Y,Z" (a point light's position),
// or "dir:X,Y,Z" (the direction towards a directional light, any length),
// either followed by ":R,G,B" (its linear colour, default 1,1,1).
struct LightOption {
  bool directional = false;
  float xyz[3] = {0.0f, 0.0f, 0.0f};
  float rgb[3] = {1.0f, 1.0f, 1.0f};
};
Expected<LightOption> parse_light(std::string_view flag, const std::string& text);

// --threads N, the same everywhere: worker threads, 0 meaning every core
// the process may use (what JobSystem takes); at most kMaxThreads.
inline constexpr int kMaxThreads = 1024;
Expected<int> parse_threads(std::string_view flag, const std::string& text);

}  // namespace sinew::cli
