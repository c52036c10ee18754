#include "editor/cli/import_limit_flags.h"

#include <cstdint>
#include <utility>

#include "runtime/cli/option_values.h"

namespace sinew::editor {
namespace {

std::string with_default(const char* what, std::size_t value) {
  return std::string(what) + " (default " + std::to_string(value) + ")";
}

}  // namespace

ImportLimitFlags::ImportLimitFlags(cli::CommandLine& line)
    : triangles_(line.option("--max-triangles", "N",
                             with_default("glTF import limit on triangles over all mesh instances",
                                          ImportLimits{}.max_triangles))),
      clips_(line.option("--max-clips", "N",
                         with_default("glTF import limit on animations", ImportLimits{}.max_clips))),
      keys_(line.option("--max-keys", "N",
                        with_default("glTF import limit on animation keys over all channels",
                                     ImportLimits{}.max_keys))),
      nodes_(line.option("--max-nodes", "N", with_default("glTF import limit on nodes", ImportLimits{}.max_nodes))),
      bytes_(line.option("--max-bytes", "N",
                         with_default("glTF import limit on the bytes read, the file and its external buffers",
                                      ImportLimits{}.max_bytes))) {}

Status ImportLimitFlags::apply(ImportLimits& limits) const {
  const std::pair<const char*, std::pair<const std::optional<std::string>*, std::size_t*>> options[] = {
      {"--max-triangles", {&triangles_, &limits.max_triangles}},
      {"--max-clips", {&clips_, &limits.max_clips}},
      {"--max-keys", {&keys_, &limits.max_keys}},
      {"--max-nodes", {&nodes_, &limits.max_nodes}},
      {"--max-bytes", {&bytes_, &limits.max_bytes}}};
  for (const auto& [flag, target] : options) {
    if (const std::optional<std::string>& text = *target.first) {
      SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int(flag, *text, 1, std::int64_t{1} << 40));
      *target.second = static_cast<std::size_t>(n);
    }
  }
  return {};
}

}  // namespace sinew::editor
