// What every part of the glTF import shares: the parsed model, the file's
// name and the limits (Ctx, which words each error and limit message), and
// idx() / num(), which spell fields and values in those messages. Separate
// so that every part (gltf_accessors.h ... gltf_mesh.h) reports alike.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

#include <tiny_gltf.h>

#include "editor/import/gltf_importer.h"
#include "runtime/core/expected.h"

namespace sinew::editor::gltf_detail {

inline std::string idx(std::string_view base, std::size_t i) {
  std::string s(base);
  s += '[';
  s += std::to_string(i);
  s += ']';
  return s;
}

inline std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct Ctx {
  const tinygltf::Model& model;
  const std::string& file;
  const ImportLimits& limits;

  // The error for a limit, naming the option that raises it.
  Status limit(std::string_view field, std::size_t value, std::string_view what, std::size_t max,
               std::string_view option) const {
    return make_error(ErrorCode::kLimitExceeded, file, field, std::to_string(value),
                      "more " + std::string(what) + " than the import limit of " + std::to_string(max) +
                          " (raise it with " + std::string(option) + ")");
  }

  Status error(ErrorCode code, std::string_view field, std::string_view value,
               std::string_view detail) const {
    return make_error(code, file, field, value, detail);
  }
};

}  // namespace sinew::editor::gltf_detail
