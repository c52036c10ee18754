// Pre-validation (cal3d_validate.h): ByteWalker and the walks of the binary
// layouts, XrfChecker for XML materials, and validate_binary choosing by magic.
#include "editor/import/cal3d_validate.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <string_view>
#include <system_error>
#include <vector>

#include "editor/import/cal3d_files.h"
#include "editor/import/cal3d_xml_check.h"

namespace sinew::editor::cal3d_detail {
namespace {

namespace fs = std::filesystem;

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
// are XML (checked by extension below) or binary .crf materials (left to Cal3D).
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

}  // namespace

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
  // Cal3D picks its XML loaders by extension, so the extension decides
  // which XML check a file gets (see XrfChecker and cal3d_xml_check.h).
  if (walk == nullptr) {
    const std::string ext = lower(fs::path(path).extension().string());
    if (ext == ".xrf") return XrfChecker(bytes, path).check();
    if (ext == ".xsf") return check_cal3d_xml(bytes, path, Cal3dXmlKind::kSkeleton);
    if (ext == ".xaf") return check_cal3d_xml(bytes, path, Cal3dXmlKind::kAnimation);
    if (ext == ".xmf") return check_cal3d_xml(bytes, path, Cal3dXmlKind::kMesh);
    return {};  // binary materials: Cal3D checks those
  }
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

}  // namespace sinew::editor::cal3d_detail
