// The glTF import limits as options (--max-triangles, --max-clips,
// --max-keys, --max-nodes, --max-bytes), declared the same way by every
// command that imports a model.
#pragma once

#include <optional>
#include <string>

#include "editor/import/gltf_importer.h"
#include "runtime/cli/command_line.h"
#include "runtime/core/status.h"

namespace sinew::editor {

class ImportLimitFlags {
 public:
  explicit ImportLimitFlags(cli::CommandLine& line);
  // The limits given into `limits` (each at least 1); the others stay.
  Status apply(ImportLimits& limits) const;

 private:
  const std::optional<std::string>& triangles_;
  const std::optional<std::string>& clips_;
  const std::optional<std::string>& keys_;
  const std::optional<std::string>& nodes_;
  const std::optional<std::string>& bytes_;
};

}  // namespace sinew::editor
