#include "editor/import/cal3d_importer.h"
#include "runtime/io/regular_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <list>
#include <memory>
#include <new>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include <cal3d/cal3d.h>
#include <cal3d/corekeyframe.h>
#include <cal3d/coretrack.h>

namespace sinew::editor {
namespace {

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

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// See the header: Cal3D's quaternions rotate as the conjugate of glm's.
Quat to_quat(const CalQuaternion& q) { return Quat(q.w, -q.x, -q.y, -q.z); }
Vec3 to_vec3(const CalVector& v) { return Vec3(v.x, v.y, v.z); }

// Cal3D reports failures through a global "last error"; turn it into a
// Status naming our file (Cal3D's own file/line is its source file, useless
// to a user, so it is left out).
Status cal3d_error(const std::string& file, std::string_view what) {
  const CalError::Code code = CalError::getLastErrorCode();
  ErrorCode ours = ErrorCode::kInvalidData;
  switch (code) {
    case CalError::FILE_NOT_FOUND: ours = ErrorCode::kNotFound; break;
    case CalError::INVALID_FILE_FORMAT: ours = ErrorCode::kBadMagic; break;
    case CalError::INCOMPATIBLE_FILE_VERSION: ours = ErrorCode::kUnsupportedVersion; break;
    case CalError::MEMORY_ALLOCATION_FAILED: ours = ErrorCode::kLimitExceeded; break;
    default: break;
  }
  std::string detail = "Cal3D could not load the " + std::string(what) + ": " +
                       CalError::getErrorDescription(code);
  if (!CalError::getLastErrorText().empty()) detail += " (" + CalError::getLastErrorText() + ")";
  return make_error(ours, file, "", "", detail);
}

// Cal3D's loaders open files themselves; checking first gives a clear
// kNotFound instead of Cal3D's generic message, and keeps directories
// (which some loaders would "read" as empty) out.
Status check_file(const std::string& path) { return check_regular_file(path); }

Status validate_binary(const std::string& path);

// Before each Cal3D load: the file exists and, if binary, is well formed.
// `current` records it, so an exception from inside Cal3D names the file.
Status check_cal3d_file(const std::string& path, std::string& current) {
  current = path;
  SINEW_RETURN_IF_ERROR(check_file(path));
  return validate_binary(path);
}

std::string join(const fs::path& folder, const std::string& name) {
  const fs::path p(name);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

struct ClipFile {
  std::string path;
  std::string name;
};

// The .cfg's animations first, then every <model>_*.caf/.xaf beside it.
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

// ---------------------------------------------------------------------------
// Structural check of Cal3D's binary files before Cal3D reads them.
//
// Cal3D 0.11's binary loader trusts the file: it reserves memory from counts
// it has not checked against the file size, reads on after a short read
// (leaving counts uninitialised), and CalLoader::loadCoreSubmesh indexes the
// vertex array with the first face's ids unchecked. So each .csf/.cmf/.caf
// is walked here first, with every count checked against the bytes left and
// face ids against the vertex count. The layout (identical in file versions
// 700 and 910, the ones in the test content) is: magic[4], int version, then
//   .csf: int boneCount; per bone: string name, float[3] t, float[4] r,
//         float[3] t_bs, float[4] r_bs, int parent, int childCount, int[childCount]
//   .cmf: int submeshCount; per submesh: int material, vertexCount, faceCount,
//         lodCount, springCount, texCoordCount; per vertex: float[6], int[2],
//         float[2*texCoordCount], int influenceCount, {int bone, float w}[...],
//         float physical weight if springCount > 0; springs {int[2], float[2]};
//         faces int[3]
//   .caf: float duration, int trackCount; per track: int bone, int keyCount,
//         {float time, float[3] t, float[4] r}[keyCount]
// (string = int length + length bytes ending in NUL; integers and floats
// little-endian).
// Trailing bytes are allowed, as Cal3D allows them. Files with another magic
// (XML variants, binary .crf materials) are left to Cal3D.
class ByteWalker {
 public:
  ByteWalker(const std::string& bytes, const std::string& file) : bytes_(bytes), file_(file) {}

  std::size_t left() const { return bytes_.size() - pos_; }
  const std::string& file() const { return file_; }

  Status skip(std::size_t n, std::string_view field) {
    if (n > left()) {
      return make_error(ErrorCode::kTruncated, file_, field, std::to_string(pos_),
                        "file ends after " + std::to_string(bytes_.size()) + " bytes, " +
                            std::to_string(n) + " more needed");
    }
    pos_ += n;
    return {};
  }

  Status i32(std::int32_t& out, std::string_view field) {
    const std::size_t at = pos_;
    SINEW_RETURN_IF_ERROR(skip(4, field));
    std::uint32_t u = 0;
    for (int i = 3; i >= 0; --i) u = (u << 8) | static_cast<unsigned char>(bytes_[at + static_cast<std::size_t>(i)]);
    out = static_cast<std::int32_t>(u);
    return {};
  }

  // A count whose records (each at least `min_record` bytes) must fit in
  // what is left of the file.
  Status count(std::int32_t& out, std::size_t min_record, const std::string& field) {
    SINEW_RETURN_IF_ERROR(i32(out, field));
    if (out < 0) {
      return make_error(ErrorCode::kInvalidData, file_, field, std::to_string(out), "negative count");
    }
    if (min_record != 0 && static_cast<std::size_t>(out) > left() / min_record) {
      return make_error(ErrorCode::kTruncated, file_, field, std::to_string(out),
                        "needs at least " + std::to_string(static_cast<std::size_t>(out) * min_record) +
                            " bytes, " + std::to_string(left()) + " left in the file");
    }
    return {};
  }

  // Cal3D copies a string's bytes with strlen (found by fuzzing: a name
  // without its NUL made it read past its buffer), so the stored bytes must
  // contain the terminating NUL.
  Status string(const std::string& field) {
    std::int32_t len = 0;
    SINEW_RETURN_IF_ERROR(count(len, 1, field + ".length"));
    const std::size_t at = pos_;
    SINEW_RETURN_IF_ERROR(skip(static_cast<std::size_t>(len), field));
    if (bytes_.find('\0', at) >= pos_) {
      return make_error(ErrorCode::kInvalidData, file_, field, std::to_string(len) + " bytes",
                        "string without its terminating NUL byte");
    }
    return {};
  }

 private:
  const std::string& bytes_;
  const std::string& file_;
  std::size_t pos_ = 0;
};

// Cal3D computes bone states by recursing from the roots through each
// bone's child list and looking up each bone's parent by id, unchecked
// (found by fuzzing: a parent id past the bone count crashed in
// CalCoreBone::calculateState). So parent and child ids must be in range,
// each listed child must name its lister as parent, and the parents must
// form a forest (a cycle of child lists would recurse forever).
Status check_bone_links(const std::vector<std::int32_t>& parents,
                        const std::vector<std::vector<std::int32_t>>& children, const std::string& file) {
  const auto bones = static_cast<std::int32_t>(parents.size());
  for (std::int32_t b = 0; b < bones; ++b) {
    const std::string f = "bone[" + std::to_string(b) + "]";
    const std::int32_t parent = parents[static_cast<std::size_t>(b)];
    if (parent < -1 || parent >= bones || parent == b) {
      return make_error(ErrorCode::kOutOfBounds, file, f + ".parentId", std::to_string(parent),
                        "not -1 or another bone's id (" + std::to_string(bones) + " bones)");
    }
    const auto& list = children[static_cast<std::size_t>(b)];
    for (std::size_t c = 0; c < list.size(); ++c) {
      const std::int32_t child = list[c];
      if (child < 0 || child >= bones || parents[static_cast<std::size_t>(child)] != b) {
        return make_error(ErrorCode::kInvalidData, file, f + ".children[" + std::to_string(c) + "]",
                          std::to_string(child), "not a bone whose parentId is " + std::to_string(b));
      }
    }
  }
  // Parent chains longer than the bone count loop.
  std::vector<std::uint8_t> state(parents.size(), 0);  // 0 unseen, 1 on the chain, 2 reaches a root
  for (std::size_t start = 0; start < parents.size(); ++start) {
    std::size_t b = start;
    while (state[b] == 0) {
      state[b] = 1;
      if (parents[b] < 0) break;
      b = static_cast<std::size_t>(parents[b]);
    }
    if (state[b] == 1 && parents[b] >= 0) {
      return make_error(ErrorCode::kInvalidData, file, "bone[" + std::to_string(b) + "].parentId",
                        std::to_string(parents[b]), "bone parents form a cycle");
    }
    for (b = start; state[b] == 1; b = static_cast<std::size_t>(parents[b])) {
      state[b] = 2;
      if (parents[b] < 0) break;
    }
  }
  return {};
}

Status walk_skeleton(ByteWalker& w) {
  std::int32_t bones = 0;
  // name length + 14 floats + parent + child count.
  SINEW_RETURN_IF_ERROR(w.count(bones, 4 + 14 * 4 + 8, "boneCount"));
  if (static_cast<std::size_t>(bones) > anim::kMaxJoints) {
    return make_error(ErrorCode::kLimitExceeded, w.file(), "boneCount", std::to_string(bones),
                      "more bones than a Sinew skeleton may have (" + std::to_string(anim::kMaxJoints) + ")");
  }
  std::vector<std::int32_t> parents(static_cast<std::size_t>(bones));
  std::vector<std::vector<std::int32_t>> children(static_cast<std::size_t>(bones));
  for (std::int32_t b = 0; b < bones; ++b) {
    const std::string f = "bone[" + std::to_string(b) + "]";
    SINEW_RETURN_IF_ERROR(w.string(f + ".name"));
    SINEW_RETURN_IF_ERROR(w.skip(14 * 4, f));
    SINEW_RETURN_IF_ERROR(w.i32(parents[static_cast<std::size_t>(b)], f + ".parentId"));
    std::int32_t child_count = 0;
    SINEW_RETURN_IF_ERROR(w.count(child_count, 4, f + ".childCount"));
    auto& list = children[static_cast<std::size_t>(b)];
    list.resize(static_cast<std::size_t>(child_count));
    for (std::int32_t& child : list) SINEW_RETURN_IF_ERROR(w.i32(child, f + ".children"));
  }
  return check_bone_links(parents, children, w.file());
}

Status walk_mesh(ByteWalker& w) {
  std::int32_t submeshes = 0;
  SINEW_RETURN_IF_ERROR(w.count(submeshes, 6 * 4, "submeshCount"));
  for (std::int32_t s = 0; s < submeshes; ++s) {
    const std::string f = "submesh[" + std::to_string(s) + "]";
    std::int32_t material = 0, vertices = 0, faces = 0, lods = 0, springs = 0, uv_sets = 0;
    SINEW_RETURN_IF_ERROR(w.i32(material, f + ".material"));
    SINEW_RETURN_IF_ERROR(w.count(vertices, 8 * 4 + 4, f + ".vertexCount"));
    SINEW_RETURN_IF_ERROR(w.count(faces, 3 * 4, f + ".faceCount"));
    SINEW_RETURN_IF_ERROR(w.i32(lods, f + ".lodCount"));
    if (lods < 0) {  // Cal3D refuses it after reading earlier submeshes
      return make_error(ErrorCode::kInvalidData, "", f + ".lodCount", std::to_string(lods), "negative count");
    }
    SINEW_RETURN_IF_ERROR(w.count(springs, 4 * 4, f + ".springCount"));
    SINEW_RETURN_IF_ERROR(w.count(uv_sets, 8, f + ".textureCoordinateCount"));
    const std::size_t per_vertex = 8 * 4 + static_cast<std::size_t>(uv_sets) * 8 + 4;
    if (static_cast<std::size_t>(vertices) > w.left() / per_vertex) {
      return make_error(ErrorCode::kTruncated, "", f + ".vertexCount", std::to_string(vertices),
                        "more vertices than the file has bytes for");
    }
    for (std::int32_t v = 0; v < vertices; ++v) {
      const std::string vf = f + ".vertex[" + std::to_string(v) + "]";
      SINEW_RETURN_IF_ERROR(w.skip(8 * 4 + static_cast<std::size_t>(uv_sets) * 8, vf));
      std::int32_t influences = 0;
      SINEW_RETURN_IF_ERROR(w.count(influences, 8, vf + ".influenceCount"));
      SINEW_RETURN_IF_ERROR(w.skip(static_cast<std::size_t>(influences) * 8, vf + ".influences"));
      if (springs > 0) SINEW_RETURN_IF_ERROR(w.skip(4, vf + ".physicalWeight"));
    }
    for (std::int32_t k = 0; k < springs; ++k) {
      const std::string sf = f + ".spring[" + std::to_string(k) + "]";
      for (int c = 0; c < 2; ++c) {
        std::int32_t id = 0;
        SINEW_RETURN_IF_ERROR(w.i32(id, sf + ".vertex"));
        if (id < 0 || id >= vertices) {
          return make_error(ErrorCode::kOutOfBounds, "", sf + ".vertex[" + std::to_string(c) + "]",
                            std::to_string(id), "past the submesh's " + std::to_string(vertices) + " vertices");
        }
      }
      SINEW_RETURN_IF_ERROR(w.skip(8, sf));
    }
    for (std::int32_t t = 0; t < faces; ++t) {
      for (int c = 0; c < 3; ++c) {
        const std::string ff = f + ".face[" + std::to_string(t) + "].vertex[" + std::to_string(c) + "]";
        std::int32_t id = 0;
        SINEW_RETURN_IF_ERROR(w.i32(id, ff));
        if (id < 0 || id >= vertices) {
          return make_error(ErrorCode::kOutOfBounds, "", ff, std::to_string(id),
                            "past the submesh's " + std::to_string(vertices) + " vertices");
        }
      }
    }
  }
  return {};
}

Status walk_animation(ByteWalker& w) {
  SINEW_RETURN_IF_ERROR(w.skip(4, "duration"));
  std::int32_t tracks = 0;
  SINEW_RETURN_IF_ERROR(w.count(tracks, 8, "trackCount"));
  for (std::int32_t t = 0; t < tracks; ++t) {
    const std::string f = "track[" + std::to_string(t) + "]";
    std::int32_t bone = 0, keys = 0;
    SINEW_RETURN_IF_ERROR(w.i32(bone, f + ".bone"));
    // Cal3D rejects a negative id too, but leaks the tracks read before it
    // (found by fuzzing). Ids past the skeleton are checked after loading.
    if (bone < 0) {
      return make_error(ErrorCode::kOutOfBounds, "", f + ".bone", std::to_string(bone), "negative bone id");
    }
    SINEW_RETURN_IF_ERROR(w.count(keys, 8 * 4, f + ".keyframeCount"));
    // Cal3D rejects it too, but leaks the track doing so.
    if (keys == 0) {
      return make_error(ErrorCode::kInvalidData, "", f + ".keyframeCount", "0", "a track needs a key");
    }
    SINEW_RETURN_IF_ERROR(w.skip(static_cast<std::size_t>(keys) * 8 * 4, f + ".keyframes"));
  }
  return {};
}

// Far beyond any character file; keeps a stray huge file from being read
// into memory whole.
constexpr std::uintmax_t kMaxCal3dFileBytes = 512u << 20;

// ---------------------------------------------------------------------------
// Structural check of XML materials (.xrf) before Cal3D reads them.
//
// Cal3D 0.11's XML material loader dereferences what it looks up without
// checking it: a missing HEADER attribute (strcasecmp on null), a missing
// element or an element without text (FirstChild()->ToText() on null). So
// an .xrf must have exactly the form Cal3D itself writes, which is all it
// reliably reads:
//   <HEADER MAGIC="XRF" VERSION="n" />
//   <MATERIAL NUMMAPS="n">
//     <AMBIENT>r g b a</AMBIENT> <DIFFUSE>..</DIFFUSE> <SPECULAR>..</SPECULAR>
//     <SHININESS>s</SHININESS> <MAP>file</MAP>...
//   </MATERIAL>
// (colours 0..255, attribute values and texts free of '<', '&' and quotes,
// whitespace between tags). Anything else is refused here, naming the
// element; Cal3D then checks the magic and version values itself.
class XrfChecker {
 public:
  XrfChecker(std::string_view text, const std::string& file) : text_(text), file_(file) {}

  Status check() {
    SINEW_RETURN_IF_ERROR(open_tag("HEADER", {"MAGIC", "VERSION"}, /*self_closing=*/true));
    SINEW_RETURN_IF_ERROR(open_tag("MATERIAL", {"NUMMAPS"}, /*self_closing=*/false));
    SINEW_RETURN_IF_ERROR(text_element("AMBIENT", &XrfChecker::is_colour));
    SINEW_RETURN_IF_ERROR(text_element("DIFFUSE", &XrfChecker::is_colour));
    SINEW_RETURN_IF_ERROR(text_element("SPECULAR", &XrfChecker::is_colour));
    SINEW_RETURN_IF_ERROR(text_element("SHININESS", &XrfChecker::is_number));
    skip_space();
    while (rest().substr(0, 5) == "<MAP>") {
      SINEW_RETURN_IF_ERROR(text_element("MAP", &XrfChecker::is_plain_text));
      skip_space();
    }
    SINEW_RETURN_IF_ERROR(literal("</MATERIAL>", "MATERIAL"));
    skip_space();
    if (!rest().empty()) return refuse("MATERIAL", "text after </MATERIAL>");
    return {};
  }

 private:
  std::string_view rest() const { return text_.substr(pos_); }
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_])) != 0) ++pos_;
  }
  Status refuse(std::string_view element, std::string_view detail) const {
    return make_error(ErrorCode::kInvalidData, file_, element, "byte " + std::to_string(pos_),
                      std::string(detail) + " (Cal3D's XML material loader cannot read it safely)");
  }
  Status literal(std::string_view expected, std::string_view element) {
    skip_space();
    if (rest().substr(0, expected.size()) != expected) {
      return refuse(element, "expected '" + std::string(expected) + "'");
    }
    pos_ += expected.size();
    return {};
  }
  static bool is_plain_text(std::string_view s) {
    return s.find_first_not_of(" \t\r\n") != std::string_view::npos &&
           s.find_first_of("<&\"") == std::string_view::npos;
  }
  static bool is_number(std::string_view s) {
    s = trim(s);
    float v = 0.0f;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return ec == std::errc() && end == s.data() + s.size() && std::isfinite(v);
  }
  static bool is_colour(std::string_view s) {
    int channels = 0;
    for (s = trim(s); !s.empty(); s = trim(s)) {
      const std::size_t n = std::min(s.find_first_of(" \t\r\n"), s.size());
      int v = -1;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + n, v);
      if (ec != std::errc() || end != s.data() + n || v < 0 || v > 255) return false;
      ++channels;
      s.remove_prefix(n);
    }
    return channels == 4;
  }
  // <NAME A="v" B="v" ...> or .../>, with every attribute of `required`.
  Status open_tag(std::string_view name, std::initializer_list<std::string_view> required,
                  bool self_closing) {
    SINEW_RETURN_IF_ERROR(literal("<" + std::string(name), name));
    std::set<std::string, std::less<>> seen;
    for (;;) {
      skip_space();
      if (rest().substr(0, 2) == "/>" || rest().substr(0, 1) == ">") break;
      const std::size_t eq = rest().find("=\"");
      if (eq == std::string_view::npos || eq == 0) return refuse(name, "malformed attribute");
      const std::string_view attribute = rest().substr(0, eq);
      if (attribute.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_") !=
          std::string_view::npos) {
        return refuse(name, "malformed attribute name");
      }
      pos_ += eq + 2;
      const std::size_t close = rest().find('"');
      if (close == std::string_view::npos || rest().substr(0, close).find_first_of("<&") != std::string_view::npos) {
        return refuse(name, "unterminated attribute " + std::string(attribute));
      }
      if (!seen.emplace(attribute).second) return refuse(name, "attribute " + std::string(attribute) + " given twice");
      pos_ += close + 1;
    }
    for (std::string_view r : required) {
      if (seen.count(r) == 0) return refuse(name, "missing attribute " + std::string(r));
    }
    return literal(self_closing ? "/>" : ">", name);
  }
  // <NAME>text</NAME> with text accepted by `valid`.
  Status text_element(std::string_view name, bool (*valid)(std::string_view)) {
    SINEW_RETURN_IF_ERROR(literal("<" + std::string(name) + ">", name));
    const std::size_t end = rest().find('<');
    if (end == std::string_view::npos || !is_plain_text(rest().substr(0, end)) ||
        !valid(rest().substr(0, end))) {
      return refuse(name, "missing or malformed text");
    }
    pos_ += end;
    return literal("</" + std::string(name) + ">", name);
  }

  std::string_view text_;
  const std::string& file_;
  std::size_t pos_ = 0;
};

Status validate_binary(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return make_error(ErrorCode::kIoError, path, "", "", ec.message());
  if (size > kMaxCal3dFileBytes) {
    return make_error(ErrorCode::kLimitExceeded, path, "size", std::to_string(size),
                      "larger than any Cal3D character file Sinew accepts");
  }
  std::ifstream in(path, std::ios::binary);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) {
    return make_error(ErrorCode::kIoError, path, "", "", "read failed");
  }
  const std::string_view magic(bytes.data(), std::min<std::size_t>(bytes.size(), 4));
  using Walk = Status (*)(ByteWalker&);
  Walk walk = nullptr;
  if (magic == std::string_view("CSF\0", 4)) walk = walk_skeleton;
  if (magic == std::string_view("CMF\0", 4)) walk = walk_mesh;
  if (magic == std::string_view("CAF\0", 4)) walk = walk_animation;
  if (bytes.size() < 4) {
    return make_error(ErrorCode::kTruncated, path, "magic", std::to_string(bytes.size()) + " bytes",
                      "too short for a Cal3D file");
  }
  // Cal3D picks its XML loaders by extension; only the material's is
  // guarded here (see XrfChecker).
  if (walk == nullptr && lower(fs::path(path).extension().string()) == ".xrf") {
    return XrfChecker(bytes, path).check();
  }
  if (walk == nullptr) return {};  // other XML files, binary materials: Cal3D checks those
  ByteWalker w(bytes, path);
  SINEW_RETURN_IF_ERROR(w.skip(4, "magic"));
  std::int32_t version = 0;
  SINEW_RETURN_IF_ERROR(w.i32(version, "version"));
  if (Status s = walk(w); !s.ok()) return s.with_file(path);
  // Cal3D's loader stops where the data ends and ignores the rest.
  if (w.left() != 0) {
    return make_error(ErrorCode::kInvalidData, path, "size", std::to_string(bytes.size()) + " bytes",
                      std::to_string(w.left()) + " bytes follow the end of the data at byte " +
                          std::to_string(bytes.size() - w.left()));
  }
  return {};
}

Expected<anim::Skeleton> convert_skeleton(CalCoreSkeleton& core, const std::string& file,
                                          std::vector<int>& raw_to_sorted) {
  std::vector<CalCoreBone*>& bones = core.getVectorCoreBone();
  if (bones.size() > anim::kMaxJoints) {
    return make_error(ErrorCode::kLimitExceeded, file, "bones", std::to_string(bones.size()),
                      "more bones than Sinew supports (" + std::to_string(anim::kMaxJoints) + ")");
  }
  anim::RawSkeleton raw;
  raw.joints.resize(bones.size());
  for (std::size_t i = 0; i < bones.size(); ++i) {
    CalCoreBone* b = bones[i];
    const std::string field = "bone[" + std::to_string(i) + "]";
    if (b == nullptr) return make_error(ErrorCode::kInvalidData, file, field, "", "missing bone");
    anim::RawJoint& j = raw.joints[i];
    j.name = b->getName();
    const int parent = b->getParentId();
    // Cal3D writes -1 for roots; anything else negative is corrupt, and
    // Skeleton::build reports indices past the end.
    if (parent < -1) {
      return make_error(ErrorCode::kOutOfBounds, file, field + ".parent", std::to_string(parent),
                        "negative parent id");
    }
    j.parent = parent < 0 ? anim::kNoParent : parent;
    j.rest.translation = to_vec3(b->getTranslation());
    j.rest.rotation = to_quat(b->getRotation());
    // Bone space maps model space to the bone: p_bone = R_bs p + t_bs.
    j.inverse_bind = Affine3::from_trs(to_vec3(b->getTranslationBoneSpace()),
                                       to_quat(b->getRotationBoneSpace()), Vec3(1.0f));
    if (!finite(j.rest.translation) || !finite(to_vec3(b->getTranslationBoneSpace()))) {
      return make_error(ErrorCode::kInvalidData, file, field + ".translation", "",
                        "non-finite translation");
    }
  }
  return anim::Skeleton::build(raw, file, &raw_to_sorted);
}

struct MeshContext {
  SkinnedMesh* mesh = nullptr;
  const std::vector<int>* raw_to_sorted = nullptr;
  std::size_t material_count = 0;   // materials loaded from the .cfg
  bool uses_default_material = false;
};

Status convert_mesh(CalCoreMesh& core, const std::string& file, MeshContext& ctx) {
  SkinnedMesh& m = *ctx.mesh;
  const std::vector<int>& remap = *ctx.raw_to_sorted;
  std::vector<CalCoreSubmesh*>& submeshes = core.getVectorCoreSubmesh();
  for (std::size_t s = 0; s < submeshes.size(); ++s) {
    CalCoreSubmesh* sub = submeshes[s];
    const std::string sfield = "submesh[" + std::to_string(s) + "]";
    if (sub == nullptr) return make_error(ErrorCode::kInvalidData, file, sfield, "", "missing");
    std::vector<CalCoreSubmesh::Vertex>& verts = sub->getVectorVertex();
    std::vector<CalCoreSubmesh::Face>& faces = sub->getVectorFace();
    std::vector<std::vector<CalCoreSubmesh::TextureCoordinate>>& uv_sets =
        sub->getVectorVectorTextureCoordinate();
    const std::size_t base = m.positions.size();
    if (base + verts.size() > UINT32_MAX) {
      return make_error(ErrorCode::kLimitExceeded, file, sfield + ".vertices",
                        std::to_string(verts.size()), "too many vertices");
    }
    // UVs: each submesh's first set. Once any submesh has UVs, vertices of
    // submeshes without them get (0,0), so the arrays stay parallel.
    const bool has_uv = !uv_sets.empty() && uv_sets[0].size() == verts.size();
    if (has_uv && m.uvs.size() < base) m.uvs.resize(base, Vec2(0.0f));

    for (std::size_t v = 0; v < verts.size(); ++v) {
      const CalCoreSubmesh::Vertex& cv = verts[v];
      const std::string vfield = sfield + ".vertex[" + std::to_string(v) + "]";
      const Vec3 p = to_vec3(cv.position);
      Vec3 n = to_vec3(cv.normal);
      if (!finite(p) || !finite(n)) {
        return make_error(ErrorCode::kInvalidData, file, vfield, "", "non-finite position or normal");
      }
      const float len = glm::length(n);
      // A zero normal cannot be made unit; any unit vector keeps the
      // SkinnedMesh invariant and the vertex is degenerate for shading anyway.
      n = len > 0.0f ? n / len : Vec3(0.0f, 0.0f, 1.0f);
      m.positions.push_back(p);
      m.normals.push_back(n);
      if (has_uv) {
        m.uvs.emplace_back(uv_sets[0][v].u, uv_sets[0][v].v);
      } else if (!m.uvs.empty()) {
        m.uvs.emplace_back(0.0f, 0.0f);
      }

      // Influences: keep the kMaxInfluences largest, renormalised.
      std::vector<std::pair<float, int>> infl;
      infl.reserve(cv.vectorInfluence.size());
      for (std::size_t k = 0; k < cv.vectorInfluence.size(); ++k) {
        const CalCoreSubmesh::Influence& in = cv.vectorInfluence[k];
        const std::string ifield = vfield + ".influence[" + std::to_string(k) + "]";
        if (in.boneId < 0 || static_cast<std::size_t>(in.boneId) >= remap.size()) {
          return make_error(ErrorCode::kOutOfBounds, file, ifield + ".bone",
                            std::to_string(in.boneId),
                            "no such bone (" + std::to_string(remap.size()) + " bones)");
        }
        if (!std::isfinite(in.weight) || in.weight < 0.0f) {
          return make_error(ErrorCode::kInvalidData, file, ifield + ".weight",
                            std::to_string(in.weight), "weight must be finite and >= 0");
        }
        if (in.weight > 0.0f) infl.emplace_back(in.weight, remap[static_cast<std::size_t>(in.boneId)]);
      }
      // stable_sort keeps file order among equal weights: deterministic.
      std::stable_sort(infl.begin(), infl.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      if (infl.size() > static_cast<std::size_t>(kMaxInfluences)) infl.resize(kMaxInfluences);
      double sum = 0.0;
      for (const auto& i : infl) sum += static_cast<double>(i.first);
      // Cal3D leaves a vertex without influences in place (model space);
      // Sinew has no "no bone" slot, and binding it to some bone would move
      // it, so such a mesh is rejected rather than silently changed.
      if (infl.empty() || !(sum > 0.0)) {
        return make_error(ErrorCode::kInvalidData, file, vfield + ".influences", "0",
                          "vertex has no bone influence with a positive weight");
      }
      std::array<std::uint16_t, kMaxInfluences> joints{};
      std::array<float, kMaxInfluences> weights{};
      for (std::size_t k = 0; k < infl.size(); ++k) {
        joints[k] = static_cast<std::uint16_t>(infl[k].second);
        weights[k] = infl[k].first;  // renormalised with every importer's rule below
      }
      m.joints.push_back(joints);
      m.weights.push_back(weights);
    }

    int thread = sub->getCoreMaterialThreadId();
    std::uint32_t material = 0;
    if (thread >= 0 && static_cast<std::size_t>(thread) < ctx.material_count) {
      material = static_cast<std::uint32_t>(thread);
    } else {
      material = static_cast<std::uint32_t>(ctx.material_count);  // the white default
      ctx.uses_default_material = true;
    }
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::array<std::uint32_t, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        const auto id = static_cast<long long>(faces[f].vertexId[c]);
        if (id < 0 || static_cast<std::size_t>(id) >= verts.size()) {
          return make_error(ErrorCode::kOutOfBounds, file,
                            sfield + ".face[" + std::to_string(f) + "].vertex[" +
                                std::to_string(c) + "]",
                            std::to_string(id),
                            "past the submesh's " + std::to_string(verts.size()) + " vertices");
        }
        tri[static_cast<std::size_t>(c)] = static_cast<std::uint32_t>(base + static_cast<std::size_t>(id));
      }
      m.triangles.push_back(tri);
      m.triangle_material.push_back(material);
    }
  }
  return {};
}

Expected<anim::Clip> convert_clip(CalCoreAnimation& core, const std::string& name,
                                  const std::string& file, const anim::Skeleton& skeleton,
                                  const std::vector<int>& remap) {
  anim::RawClip raw;
  raw.name = name;
  const float duration = core.getDuration();
  std::size_t t = 0;
  for (CalCoreTrack* track : core.getListCoreTrack()) {
    const std::string tfield = "track[" + std::to_string(t++) + "]";
    if (track == nullptr) return make_error(ErrorCode::kInvalidData, file, tfield, "", "missing");
    const int bone = track->getCoreBoneId();
    if (bone < 0 || static_cast<std::size_t>(bone) >= remap.size()) {
      return make_error(ErrorCode::kOutOfBounds, file, tfield + ".bone", std::to_string(bone),
                        "no such bone (" + std::to_string(remap.size()) + " bones)");
    }
    anim::JointTracks jt;
    jt.joint = remap[static_cast<std::size_t>(bone)];
    jt.translation.interpolation = anim::Interpolation::kLinear;
    jt.rotation.interpolation = anim::Interpolation::kLinear;
    const int count = track->getCoreKeyframeCount();
    // Cal3D samples nothing sensible from a track without keys; it animates
    // nothing, so it is left out.
    if (count <= 0) continue;
    for (int k = 0; k < count; ++k) {
      CalCoreKeyframe* key = track->getCoreKeyframe(k);
      if (key == nullptr) {
        return make_error(ErrorCode::kInvalidData, file, tfield + ".key[" + std::to_string(k) + "]",
                          "", "missing");
      }
      const float time = key->getTime();
      const Vec3 tr = to_vec3(key->getTranslation());
      const Quat rot = to_quat(key->getRotation());
      // Equal times: Cal3D samples the last of them at and after that time
      // (upper-bound search), so keeping the last reproduces it exactly.
      // Other ordering problems are left for Clip::build to report.
      if (!jt.translation.times.empty() && jt.translation.times.back() == time) {
        jt.translation.values.back() = tr;
        jt.rotation.values.back() = rot;
        continue;
      }
      jt.translation.times.push_back(time);
      jt.translation.values.push_back(tr);
      jt.rotation.times.push_back(time);
      jt.rotation.values.push_back(rot);
    }
    // Cal3D's cycles loop at the header duration, usually one frame past
    // the last key: CalMixer::blendCycle appends to each such track a key at
    // the duration holding the first key's value (Cal3D 0.11, checked by the
    // oracle test), so the last frame blends back into the first. Doing the
    // same makes the clip's duration Cal3D's and its loop seamless.
    if (std::isfinite(duration) && duration > jt.translation.times.back()) {
      jt.translation.times.push_back(duration);
      jt.translation.values.push_back(jt.translation.values.front());
      jt.rotation.times.push_back(duration);
      jt.rotation.values.push_back(jt.rotation.values.front());
    }
    raw.tracks.push_back(std::move(jt));
  }
  return anim::Clip::build(std::move(raw), skeleton, file);
}

// Cal3D 0.11's ~CalCoreAnimation does not delete its tracks (LeakSanitizer
// shows every track and keyframe lost), so the owner frees them; the list is
// emptied, so a Cal3D whose destructor does delete them finds nothing left.
class CoreModelTrackReleaser {
 public:
  explicit CoreModelTrackReleaser(CalCoreModel& core) : core_(core) {}
  CoreModelTrackReleaser(const CoreModelTrackReleaser&) = delete;
  CoreModelTrackReleaser& operator=(const CoreModelTrackReleaser&) = delete;
  ~CoreModelTrackReleaser() {
    for (int i = 0; i < core_.getCoreAnimationCount(); ++i) {
      CalCoreAnimation* anim = core_.getCoreAnimation(i);
      if (anim == nullptr) continue;
      std::list<CalCoreTrack*>& tracks = anim->getListCoreTrack();
      for (CalCoreTrack* track : tracks) {
        if (track == nullptr) continue;
        track->destroy();
        delete track;
      }
      tracks.clear();
    }
  }

 private:
  CalCoreModel& core_;
};

Expected<ImportedModel> import_impl(const std::string& cfg_path, std::string& current) {
  SINEW_RETURN_IF_ERROR(check_file(cfg_path));
  std::ifstream in(cfg_path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIoError, cfg_path, "", "", "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) return make_error(ErrorCode::kIoError, cfg_path, "", "", "read failed");
  SINEW_ASSIGN_OR_RETURN(Cal3dConfig cfg, parse_cal3d_config(text.str(), cfg_path));

  const fs::path folder = fs::path(cfg_path).parent_path();
  const std::string model_name = fs::path(cfg_path).stem().string();

  CalCoreModel core(model_name);
  const CoreModelTrackReleaser release_tracks(core);

  // Skeleton first whatever the .cfg order: meshes and animations refer to it.
  const std::string skeleton_file = join(folder, cfg.skeleton);
  SINEW_RETURN_IF_ERROR(check_cal3d_file(skeleton_file, current));
  if (!core.loadCoreSkeleton(skeleton_file)) return cal3d_error(skeleton_file, "skeleton");
  if (core.getCoreSkeleton() == nullptr) {
    return make_error(ErrorCode::kInvalidData, skeleton_file, "", "", "Cal3D loaded no skeleton");
  }

  std::vector<std::string> mesh_files;
  std::vector<int> mesh_ids;
  for (const std::string& m : cfg.meshes) {
    mesh_files.push_back(join(folder, m));
    SINEW_RETURN_IF_ERROR(check_cal3d_file(mesh_files.back(), current));
    const int id = core.loadCoreMesh(mesh_files.back());
    if (id < 0) return cal3d_error(mesh_files.back(), "mesh");
    mesh_ids.push_back(id);
  }

  std::vector<std::string> material_files;
  std::vector<int> material_ids;
  for (const std::string& m : cfg.materials) {
    material_files.push_back(join(folder, m));
    SINEW_RETURN_IF_ERROR(check_cal3d_file(material_files.back(), current));
    const int id = core.loadCoreMaterial(material_files.back());
    if (id < 0) return cal3d_error(material_files.back(), "material");
    material_ids.push_back(id);
  }

  SINEW_ASSIGN_OR_RETURN(const std::vector<ClipFile> clips,
                         clip_files(cfg, folder, model_name, cfg_path));
  std::vector<int> clip_ids;
  for (const ClipFile& c : clips) {
    SINEW_RETURN_IF_ERROR(check_cal3d_file(c.path, current));
    const int id = core.loadCoreAnimation(c.path);
    if (id < 0) return cal3d_error(c.path, "animation");
    clip_ids.push_back(id);
  }

  current = cfg_path;
  // After loading everything, so meshes, skeleton and keyframes all scale.
  if (cfg.scale != 1.0f) core.scale(cfg.scale);

  ImportedModel out;
  out.source = cfg_path;
  std::vector<int> raw_to_sorted;
  SINEW_ASSIGN_OR_RETURN(out.skeleton,
                         convert_skeleton(*core.getCoreSkeleton(), skeleton_file, raw_to_sorted));

  MeshContext ctx;
  ctx.mesh = &out.mesh;
  ctx.raw_to_sorted = &raw_to_sorted;
  ctx.material_count = material_ids.size();
  for (std::size_t i = 0; i < mesh_ids.size(); ++i) {
    CalCoreMesh* mesh = core.getCoreMesh(mesh_ids[i]);
    if (mesh == nullptr) return make_error(ErrorCode::kInvalidData, mesh_files[i], "", "", "Cal3D loaded no mesh");
    SINEW_RETURN_IF_ERROR(convert_mesh(*mesh, mesh_files[i], ctx));
  }

  for (std::size_t i = 0; i < material_ids.size(); ++i) {
    CalCoreMaterial* mat = core.getCoreMaterial(material_ids[i]);
    Vec3 color(1.0f);
    if (mat != nullptr) {
      const CalCoreMaterial::Color& c = mat->getDiffuseColor();
      // Bytes 0..255 taken as linear: Cal3D's fixed-function demos feed them
      // to glMaterial unconverted.
      color = Vec3(c.red, c.green, c.blue) / 255.0f;
    }
    out.mesh.material_colors.push_back(color);
    out.material_names.push_back(fs::path(material_files[i]).stem().string());
  }
  if (ctx.uses_default_material) {
    out.mesh.material_colors.emplace_back(1.0f);
    out.material_names.emplace_back("default");
  }

  for (std::size_t i = 0; i < clips.size(); ++i) {
    CalCoreAnimation* anim = core.getCoreAnimation(clip_ids[i]);
    if (anim == nullptr) {
      return make_error(ErrorCode::kInvalidData, clips[i].path, "", "", "Cal3D loaded no animation");
    }
    SINEW_ASSIGN_OR_RETURN(anim::Clip clip, convert_clip(*anim, clips[i].name, clips[i].path,
                                                         out.skeleton, raw_to_sorted));
    out.clips.push_back(std::move(clip));
  }
  SINEW_RETURN_IF_ERROR(normalize_skin_weights(out));
  return out;
}

}  // namespace

Expected<Cal3dConfig> parse_cal3d_config(std::string_view text, std::string_view source) {
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

Expected<ImportedModel> import_cal3d(const std::string& cfg_path) {
  // Cal3D allocates with plain new and std::vector from counts in the file;
  // a corrupt count can throw. Errors are values here, so that ends as one.
  std::string current = cfg_path;
  try {
    return import_impl(cfg_path, current);
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::kLimitExceeded, current, "", "",
                      "out of memory while Cal3D loaded the file (corrupt count?)");
  } catch (const std::exception& e) {
    return make_error(ErrorCode::kInvalidData, current, "", "", std::string("Cal3D failed: ") + e.what());
  }
}

}  // namespace sinew::editor
