// File discovery (cal3d_files.h): the .cfg's parser, path joining, and the
// animations listed in the .cfg or found beside it.
#include "editor/import/cal3d_files.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <set>
#include <system_error>
#include <utility>

namespace sinew::editor::cal3d_detail {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string join(const fs::path& folder, const std::string& name) {
  const fs::path p(name);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

Expected<std::vector<ClipFile>> clip_files(const Cal3dConfig& cfg, const fs::path& folder,
                                           const std::string& model, const std::string& cfg_path) {
  std::vector<ClipFile> out;
  std::set<std::string> paths;
  std::set<std::string> names;
  const std::string prefix = model + "_";
  auto clip_name = [&](const std::string& path) {
    std::string stem = fs::path(path).stem().string();
    if (stem.size() > prefix.size() && stem.compare(0, prefix.size(), prefix) == 0) {
      stem.erase(0, prefix.size());
    }
    return stem;
  };
  // Returns false when another file already has this clip name.
  auto add = [&](const std::string& path) {
    if (paths.count(path) != 0) return true;  // listed twice: one clip
    std::string name = clip_name(path);
    if (names.count(name) != 0) return false;
    paths.insert(path);
    names.insert(name);
    out.push_back({path, std::move(name)});
    return true;
  };
  for (const std::string& a : cfg.animations) {
    const std::string path = join(folder, a);
    // Two listed files, one name: clips are looked up by name, so refuse.
    if (!add(path)) {
      return make_error(ErrorCode::kDuplicate, cfg_path, "animation", a,
                        "another listed animation already has the clip name '" + clip_name(path) + "'");
    }
  }

  std::vector<std::string> extra;
  std::error_code ec;
  for (fs::directory_iterator it(folder.empty() ? fs::path(".") : folder, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string file = it->path().filename().string();
    const std::string ext = lower(it->path().extension().string());
    if ((ext == ".caf" || ext == ".xaf") && file.size() > prefix.size() + ext.size() &&
        file.compare(0, prefix.size(), prefix) == 0 && it->is_regular_file(ec)) {
      extra.push_back(join(folder, file));
    }
  }
  // Directory order is unspecified; sorting makes clip indices ("#3") stable.
  // .caf sorts before .xaf, so the binary file wins a name clash; an extra
  // file whose name is taken is skipped (it was not asked for).
  std::sort(extra.begin(), extra.end());
  for (const std::string& e : extra) add(e);
  return out;
}

}  // namespace sinew::editor::cal3d_detail

namespace sinew::editor {

using cal3d_detail::lower;
using cal3d_detail::trim;

Expected<Cal3dConfig> parse_cal3d_config(std::string_view text, std::string_view source) {
  // Editors on Windows start UTF-8 files with a byte-order mark; left in,
  // it made the first key unknown (so skipped): a leading scale= was lost.
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  if (text.substr(0, 2) == "\xFF\xFE" || text.substr(0, 2) == "\xFE\xFF") {
    return make_error(ErrorCode::kInvalidData, source, "encoding", "UTF-16",
                      "a .cfg must be UTF-8 or ASCII text");
  }
  Cal3dConfig cfg;
  bool have_skeleton = false;
  std::size_t line_no = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view line = text.substr(0, eol);
    text = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
    ++line_no;
    const std::string field = "line " + std::to_string(line_no);
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos) {
      return make_error(ErrorCode::kInvalidData, source, field,
                        std::string(line.substr(0, std::min<std::size_t>(line.size(), 60))),
                        "expected key=value");
    }
    const std::string key = lower(std::string(trim(line.substr(0, eq))));
    const std::string_view value = trim(line.substr(eq + 1));
    const bool known = key == "scale" || key == "skeleton" || key == "mesh" || key == "animation" ||
                       key == "material";
    if (!known) continue;  // other tools' keys (path=, ...) are not errors
    if (value.empty()) {
      return make_error(ErrorCode::kInvalidData, source, field + ": " + key, "", "empty value");
    }
    if (key == "scale") {
      float s = 0.0f;
      const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), s);
      if (ec != std::errc() || ptr != value.data() + value.size() || !std::isfinite(s) || s <= 0.0f) {
        return make_error(ErrorCode::kInvalidData, source, field + ": scale", std::string(value),
                          "scale must be a finite positive number");
      }
      if (s < kMinCal3dScale || s > kMaxCal3dScale) {
        return make_error(ErrorCode::kLimitExceeded, source, field + ": scale", std::string(value),
                          "outside [1e-06, 1e+06] (kMinCal3dScale, kMaxCal3dScale), the scales the tracer "
                          "can frame and trace");
      }
      cfg.scale = s;
    } else if (key == "skeleton") {
      if (have_skeleton) {
        return make_error(ErrorCode::kDuplicate, source, field + ": skeleton", std::string(value),
                          "a model has one skeleton");
      }
      have_skeleton = true;
      cfg.skeleton = std::string(value);
    } else if (key == "mesh") {
      cfg.meshes.emplace_back(value);
    } else if (key == "animation") {
      cfg.animations.emplace_back(value);
    } else {
      cfg.materials.emplace_back(value);
    }
  }
  if (!have_skeleton) {
    return make_error(ErrorCode::kNotFound, source, "skeleton", "", "no skeleton= line");
  }
  return cfg;
}

}  // namespace sinew::editor
