#include "runtime/io/json_nesting.h"

namespace sinew {

Status check_json_nesting(std::string_view json, std::size_t max_depth, const std::string& file,
                          const std::string& field) {
  std::size_t depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        return make_error(ErrorCode::kLimitExceeded, file, field, "byte " + std::to_string(i),
                          "JSON nested deeper than " + std::to_string(max_depth) + " levels (the limit)");
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;  // unbalanced closers are the parser's to report
    }
  }
  return {};
}

}  // namespace sinew
