#include "runtime/cli/option_values.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>

#include "runtime/core/format_number.h"

namespace sinew::cli {
namespace {

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    parts.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return parts;
}

// std::from_chars of the whole string, or nothing.
template <typename T>
std::optional<T> whole_number(std::string_view text) {
  T value{};
  const char* last = text.data() + text.size();
  const auto [end, ec] = std::from_chars(text.data(), last, value);
  if (text.empty() || ec != std::errc() || end != last) return std::nullopt;
  return value;
}

}  // namespace

Expected<std::int64_t> parse_int(std::string_view flag, const std::string& text, std::int64_t lo,
                                 std::int64_t hi) {
  const auto value = whole_number<std::int64_t>(text);
  if (!value || *value < lo || *value > hi) {
    return invalid_argument(flag, text,
                            "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
  }
  return *value;
}

Expected<std::uint64_t> parse_uint64(std::string_view flag, const std::string& text) {
  const auto value = whole_number<std::uint64_t>(text);
  if (!value) return invalid_argument(flag, text, "expected a non-negative 64-bit integer");
  return *value;
}

Expected<double> parse_double(std::string_view flag, const std::string& text, double lo, double hi) {
  const auto value = whole_number<double>(text);
  if (!value || !std::isfinite(*value) || *value < lo || *value > hi) {
    return invalid_argument(flag, text, "expected a number from " + format_number(lo) + " to " + format_number(hi));
  }
  return *value;
}

Expected<std::vector<float>> parse_floats(std::string_view flag, const std::string& text, std::size_t count) {
  const std::vector<std::string> parts = split_commas(text);
  const std::string expected = "expected " + std::to_string(count) + " comma-separated numbers";
  if (parts.size() != count) {
    return invalid_argument(flag, text, expected + ", got " + std::to_string(parts.size()));
  }
  std::vector<float> values;
  for (const std::string& part : parts) {
    const auto value = whole_number<float>(part);
    if (!value || !std::isfinite(*value)) {
      return invalid_argument(flag, text, expected + " ('" + part + "' is not a finite number)");
    }
    values.push_back(*value);
  }
  return values;
}

Expected<LightOption> parse_light(std::string_view flag, const std::string& text) {
  LightOption light;
  std::string rest = text;
  if (rest.rfind("point:", 0) == 0) {
    rest = rest.substr(6);
  } else if (rest.rfind("dir:", 0) == 0) {
    light.directional = true;
    rest = rest.substr(4);
  } else if (!rest.empty() && (std::isalpha(static_cast<unsigned char>(rest[0])) != 0)) {
    return invalid_argument(flag, text, "expected X,Y,Z, point:X,Y,Z or dir:X,Y,Z, each optionally :R,G,B");
  }
  std::string colour;
  if (const std::size_t colon = rest.find(':'); colon != std::string::npos) {
    colour = rest.substr(colon + 1);
    rest = rest.substr(0, colon);
    if (colour.empty()) return invalid_argument(flag, text, "expected R,G,B after ':'");
  }
  SINEW_ASSIGN_OR_RETURN(const std::vector<float> xyz, parse_floats(flag, rest, 3));
  std::copy(xyz.begin(), xyz.end(), light.xyz);
  if (light.directional && xyz[0] == 0.0f && xyz[1] == 0.0f && xyz[2] == 0.0f) {
    return invalid_argument(flag, text, "a directional light needs a non-zero direction");
  }
  if (!colour.empty()) {
    SINEW_ASSIGN_OR_RETURN(const std::vector<float> rgb, parse_floats(flag, colour, 3));
    if (std::any_of(rgb.begin(), rgb.end(), [](float c) { return c < 0.0f; })) {
      return invalid_argument(flag, text, "a light's colour is not negative");
    }
    std::copy(rgb.begin(), rgb.end(), light.rgb);
  }
  return light;
}

Expected<std::vector<std::string>> parse_list(std::string_view flag, const std::string& text) {
  std::vector<std::string> parts = split_commas(text);
  if (std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); })) {
    return invalid_argument(flag, text, "expected a comma-separated list of non-empty names");
  }
  return parts;
}

Expected<std::vector<int>> parse_int_list(std::string_view flag, const std::string& text, int lo, int hi) {
  SINEW_ASSIGN_OR_RETURN(const std::vector<std::string> items, parse_list(flag, text));
  std::vector<int> values;
  for (const std::string& item : items) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, parse_int(flag, item, lo, hi));
    values.push_back(static_cast<int>(n));
  }
  return values;
}

Expected<Size2> parse_size(std::string_view flag, const std::string& text, int max_side, int min_side) {
  const std::size_t x = text.find('x');
  const auto fail = [&] {
    return invalid_argument(flag, text,
                            "expected WxH with W and H from " + std::to_string(min_side) + " to " +
                                std::to_string(max_side) + ", e.g. 512x512");
  };
  if (x == std::string::npos) return fail();
  const auto w = whole_number<int>(std::string_view(text).substr(0, x));
  const auto h = whole_number<int>(std::string_view(text).substr(x + 1));
  if (!w || !h || *w < min_side || *h < min_side || *w > max_side || *h > max_side) return fail();
  return Size2{*w, *h};
}

Expected<int> parse_choice(std::string_view flag, const std::string& text,
                           std::initializer_list<std::string_view> choices) {
  int index = 0;
  std::string listed;
  for (const std::string_view choice : choices) {
    if (choice == text) return index;
    listed += (index == 0 ? "" : "|") + std::string(choice);
    ++index;
  }
  return invalid_argument(flag, text, "expected one of " + listed);
}

Expected<bool> parse_on_off(std::string_view flag, const std::string& text) {
  SINEW_ASSIGN_OR_RETURN(const int index, parse_choice(flag, text, {"on", "off"}));
  return index == 0;
}

Expected<std::vector<std::string>> parse_folder_list(std::string_view flag, const std::string& text) {
  std::vector<std::string> folders;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(':', start), text.size());
    const std::string folder = text.substr(start, end - start);
    std::error_code ec;
    if (folder.empty() || !std::filesystem::is_directory(folder, ec)) {
      return invalid_argument(flag, text, "'" + folder + "' is not a folder");
    }
    folders.push_back(folder);
    start = end + 1;
  }
  return folders;
}

Expected<int> parse_threads(std::string_view flag, const std::string& text) {
  SINEW_ASSIGN_OR_RETURN(const std::int64_t n, parse_int(flag, text, 0, kMaxThreads));
  return static_cast<int>(n);
}

}  // namespace sinew::cli
