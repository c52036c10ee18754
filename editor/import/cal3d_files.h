// File discovery for a Cal3D model: the .cfg (parse_cal3d_config, declared
// in cal3d_importer.h, is defined here), the paths it names resolved against
// its folder, and the animation files to load. Separate because it decides
// which files are read; what is inside them is for the checks and Cal3D.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "editor/import/cal3d_importer.h"
#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

// The .cfg's text rules, shared with the XML material check: blanks (space,
// tab, CR) trimmed at both ends; ASCII letters lowered.
std::string_view trim(std::string_view s);
std::string lower(std::string s);

// `name` as written in the .cfg: absolute, or relative to `folder`.
std::string join(const std::filesystem::path& folder, const std::string& name);

struct ClipFile {
  std::string path;
  std::string name;
};

// The .cfg's animations first, then every <model>_*.caf/.xaf beside it.
Expected<std::vector<ClipFile>> clip_files(const Cal3dConfig& cfg, const std::filesystem::path& folder,
                                           const std::string& model, const std::string& cfg_path);

}  // namespace sinew::editor::cal3d_detail
