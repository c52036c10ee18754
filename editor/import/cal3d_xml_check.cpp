// Checks of Cal3D's XML formats (cal3d_xml_check.h) over the bounded tree of
// cal3d_xml_tree.h. The shapes are those Cal3D 0.11 writes:
//   .xsf  <SKELETON NUMBONES> <BONE ID NAME NUMCHILDS> TRANSLATION(3)
//         ROTATION(4) LOCALTRANSLATION(3) LOCALROTATION(4) PARENTID CHILDID*
//   .xaf  <ANIMATION DURATION NUMTRACKS> <TRACK BONEID NUMKEYFRAMES>
//         <KEYFRAME TIME> TRANSLATION(3) ROTATION(4)
//   .xmf  <MESH NUMSUBMESH> <SUBMESH NUMVERTICES NUMFACES MATERIAL NUMLODSTEPS
//         NUMSPRINGS NUMTEXCOORDS> <VERTEX ID NUMINFLUENCES> POS(3) NORM(3)
//         [COLLAPSEID COLLAPSECOUNT] TEXCOORD(2)* <INFLUENCE ID>w* [PHYSIQUE];
//         <SPRING VERTEXID="a b" COEF LENGTH/>; <FACE VERTEXID="a b c"/>
// each optionally after <HEADER MAGIC VERSION/> (older files).
#include "editor/import/cal3d_xml_check.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>
#include <vector>

#include "animation/skeleton.h"
#include "editor/import/cal3d_validate.h"
#include "editor/import/cal3d_xml_tree.h"

namespace sinew::editor::cal3d_detail {
namespace {

std::string_view trim_blanks(std::string_view s) {
  const std::size_t from = s.find_first_not_of(" \t\r\n");
  if (from == std::string_view::npos) return {};
  return s.substr(from, s.find_last_not_of(" \t\r\n") + 1 - from);
}

// The error of `e`, or OK: for checks whose value is not needed.
template <typename T>
Status status_of(const Expected<T>& e) {
  return e.ok() ? Status{} : e.status();
}

// A value as shown in a message: a file may put anything of any length there.
std::string shown(std::string_view value) {
  return value.size() <= 40 ? std::string(value) : std::string(value.substr(0, 40)) + "...";
}

class Checker {
 public:
  Checker(const XmlTree& tree, const std::string& file) : tree_(tree), file_(file) {}

  Status check(Cal3dXmlKind kind) {
    static constexpr std::string_view kMagic[] = {"XSF", "XAF", "XMF"};
    static constexpr std::string_view kMain[] = {"SKELETON", "ANIMATION", "MESH"};
    const auto k = static_cast<std::size_t>(kind);
    std::uint32_t main = tree_.first_root;
    if (main != kNoElement && same_name(el(main).name, "HEADER")) {
      const XmlElement& header = el(main);
      const std::string_view* magic = find_attribute(header, "MAGIC");
      if (magic == nullptr || !same_name(*magic, kMagic[k])) {
        return refuse(ErrorCode::kBadMagic, "HEADER.MAGIC", magic == nullptr ? "" : *magic,
                      "expected " + std::string(kMagic[k]));
      }
      SINEW_RETURN_IF_ERROR(status_of(int_attribute(header, "VERSION", "HEADER", 0, 1 << 30)));
      main = header.next_sibling;
    }
    if (main == kNoElement || !same_name(el(main).name, kMain[k])) {
      return refuse(ErrorCode::kInvalidData, kMain[k], main == kNoElement ? "" : el(main).name,
                    "expected the <" + std::string(kMain[k]) + "> element");
    }
    if (el(main).next_sibling != kNoElement) {
      return refuse(ErrorCode::kInvalidData, kMain[k], el(el(main).next_sibling).name,
                    "a second top-level element after <" + std::string(kMain[k]) + ">");
    }
    if (find_attribute(el(main), "VERSION") != nullptr) {
      SINEW_RETURN_IF_ERROR(status_of(int_attribute(el(main), "VERSION", std::string(kMain[k]), 0, 1 << 30)));
    }
    switch (kind) {
      case Cal3dXmlKind::kSkeleton: return skeleton(el(main));
      case Cal3dXmlKind::kAnimation: return animation(el(main));
      case Cal3dXmlKind::kMesh: return mesh(el(main));
    }
    return {};
  }

 private:
  const XmlElement& el(std::uint32_t i) const { return tree_.elements[i]; }

  std::vector<std::uint32_t> children(const XmlElement& e) const {
    std::vector<std::uint32_t> out;
    for (std::uint32_t c = e.first_child; c != kNoElement; c = el(c).next_sibling) out.push_back(c);
    return out;
  }

  Status refuse(ErrorCode code, std::string_view field, std::string_view value, const std::string& detail) const {
    return make_error(code, file_, field, shown(value), detail);
  }

  // A whole-string integer in [lo, hi].
  Expected<std::int64_t> integer(std::string_view text, const std::string& field, std::int64_t lo,
                                 std::int64_t hi) const {
    const std::string_view s = trim_blanks(text);
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) {
      return refuse(ErrorCode::kInvalidData, field, text, "not an integer");
    }
    if (v < lo || v > hi) {
      return refuse(ErrorCode::kOutOfBounds, field, text,
                    "outside " + std::to_string(lo) + ".." + std::to_string(hi));
    }
    return v;
  }

  Expected<std::int64_t> int_attribute(const XmlElement& e, std::string_view name, const std::string& path,
                                       std::int64_t lo, std::int64_t hi) const {
    const std::string field = path + "." + std::string(name);
    const std::string_view* value = find_attribute(e, name);
    if (value == nullptr) return refuse(ErrorCode::kInvalidData, field, "", "missing attribute");
    return integer(*value, field, lo, hi);
  }

  // Exactly `count` finite numbers separated by blanks (Cal3D reads them
  // with streams and atof: `abc` would be 0, `nan` and `inf` pass).
  Status numbers(std::string_view text, std::size_t count, const std::string& field) const {
    std::size_t found = 0;
    for (std::string_view s = trim_blanks(text); !s.empty(); s = trim_blanks(s)) {
      const std::size_t n = std::min(s.find_first_of(" \t\r\n"), s.size());
      std::string_view token = s.substr(0, n);
      if (token.size() > 1 && token.front() == '+') token.remove_prefix(1);
      float v = 0.0f;
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
      if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(v)) {
        return refuse(ErrorCode::kInvalidData, field, s.substr(0, n), "not a finite number");
      }
      ++found;
      s.remove_prefix(n);
    }
    if (found != count) {
      return refuse(ErrorCode::kInvalidData, field, text,
                    std::to_string(found) + " numbers where " + std::to_string(count) + " belong");
    }
    return {};
  }

  Status number_attribute(const XmlElement& e, std::string_view name, const std::string& path) const {
    const std::string field = path + "." + std::string(name);
    const std::string_view* value = find_attribute(e, name);
    if (value == nullptr) return refuse(ErrorCode::kInvalidData, field, "", "missing attribute");
    return numbers(*value, 1, field);
  }

  // The next child, which must be called `name`; `at` moves past it.
  Expected<std::uint32_t> expect(const std::vector<std::uint32_t>& list, std::size_t& at, std::string_view name,
                                 const std::string& path) const {
    if (at >= list.size() || !same_name(el(list[at]).name, name)) {
      return refuse(ErrorCode::kInvalidData, path + "." + std::string(name),
                    at < list.size() ? el(list[at]).name : "", "expected <" + std::string(name) + "> here");
    }
    return list[at++];
  }

  // A child holding `count` numbers and nothing else.
  Status numeric_child(const std::vector<std::uint32_t>& list, std::size_t& at, std::string_view name,
                       std::size_t count, const std::string& path) const {
    SINEW_ASSIGN_OR_RETURN(const std::uint32_t c, expect(list, at, name, path));
    if (el(c).first_child != kNoElement) {
      return refuse(ErrorCode::kInvalidData, path + "." + std::string(name), el(el(c).first_child).name,
                    "an element where numbers belong");
    }
    return numbers(el(c).text, count, path + "." + std::string(name));
  }

  Status no_more(const std::vector<std::uint32_t>& list, std::size_t at, const std::string& path) const {
    if (at == list.size()) return {};
    return refuse(ErrorCode::kInvalidData, path, el(list[at]).name, "unexpected element");
  }

  Status count_matches(std::int64_t declared, std::size_t present, const std::string& field) const {
    if (declared == static_cast<std::int64_t>(present)) return {};
    return refuse(ErrorCode::kInvalidData, field, std::to_string(declared),
                  std::to_string(present) + " elements present");
  }

  // The children of `e` (at `path`): as many as its attribute `count`
  // declares (within [lo, hi]), each a <child>. An element's path in
  // messages is `prefix` + "CHILD[i]".
  Expected<std::vector<std::uint32_t>> counted_children(const XmlElement& e, std::string_view count,
                                                        const std::string& path, std::int64_t lo, std::int64_t hi,
                                                        std::string_view child, const std::string& prefix) const {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t declared, int_attribute(e, count, path, lo, hi));
    std::vector<std::uint32_t> list = children(e);
    SINEW_RETURN_IF_ERROR(count_matches(declared, list.size(), path + "." + std::string(count)));
    for (std::size_t i = 0; i < list.size(); ++i) {
      const XmlElement& c = el(list[i]);
      if (!same_name(c.name, child)) {
        return refuse(ErrorCode::kInvalidData, element_path(prefix, child, i), c.name,
                      "expected <" + std::string(child) + ">");
      }
    }
    return list;
  }
  static std::string element_path(const std::string& prefix, std::string_view child, std::size_t i) {
    return prefix + std::string(child) + "[" + std::to_string(i) + "]";
  }

  Status skeleton(const XmlElement& s) const {
    constexpr auto kMax = static_cast<std::int64_t>(anim::kMaxJoints);
    SINEW_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> bones,
                           counted_children(s, "NUMBONES", "SKELETON", 0, kMax, "BONE", ""));
    std::vector<std::int32_t> parents(bones.size());
    std::vector<std::vector<std::int32_t>> links(bones.size());
    for (std::size_t b = 0; b < bones.size(); ++b) {
      const XmlElement& bone = el(bones[b]);
      const std::string path = element_path("", "BONE", b);
      // Links name bones by position, so an ID elsewhere would mislead.
      SINEW_ASSIGN_OR_RETURN(const std::int64_t id, int_attribute(bone, "ID", path, 0, kMax));
      if (id != static_cast<std::int64_t>(b)) {
        return refuse(ErrorCode::kInvalidData, path + ".ID", std::to_string(id), "bones must be listed in id order");
      }
      if (find_attribute(bone, "NAME") == nullptr) {
        return refuse(ErrorCode::kInvalidData, path + ".NAME", "", "missing attribute");
      }
      const std::vector<std::uint32_t> parts = children(bone);
      std::size_t at = 0;
      SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "TRANSLATION", 3, path));
      SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "ROTATION", 4, path));
      SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "LOCALTRANSLATION", 3, path));
      SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "LOCALROTATION", 4, path));
      SINEW_ASSIGN_OR_RETURN(const std::uint32_t parent, expect(parts, at, "PARENTID", path));
      SINEW_ASSIGN_OR_RETURN(const std::int64_t parent_id, integer(el(parent).text, path + ".PARENTID", -1, kMax));
      parents[b] = static_cast<std::int32_t>(parent_id);
      while (at < parts.size()) {
        const std::string field = path + ".CHILDID[" + std::to_string(links[b].size()) + "]";
        SINEW_ASSIGN_OR_RETURN(const std::uint32_t child, expect(parts, at, "CHILDID", path));
        SINEW_ASSIGN_OR_RETURN(const std::int64_t child_id, integer(el(child).text, field, 0, kMax));
        links[b].push_back(static_cast<std::int32_t>(child_id));
      }
      if (find_attribute(bone, "NUMCHILDS") != nullptr) {
        SINEW_ASSIGN_OR_RETURN(const std::int64_t childs, int_attribute(bone, "NUMCHILDS", path, 0, kMax));
        SINEW_RETURN_IF_ERROR(count_matches(childs, links[b].size(), path + ".NUMCHILDS"));
      }
    }
    return check_bone_links(parents, links, file_);
  }

  Status animation(const XmlElement& a) const {
    SINEW_RETURN_IF_ERROR(number_attribute(a, "DURATION", "ANIMATION"));
    constexpr auto kIntMax = std::numeric_limits<std::int32_t>::max();
    SINEW_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> tracks,
                           counted_children(a, "NUMTRACKS", "ANIMATION", 0, kIntMax, "TRACK", ""));
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      const XmlElement& track = el(tracks[t]);
      const std::string path = element_path("", "TRACK", t);
      // Ids past the skeleton are refused after loading, as for .caf files.
      SINEW_RETURN_IF_ERROR(status_of(
          int_attribute(track, "BONEID", path, 0, static_cast<std::int64_t>(anim::kMaxJoints))));
      SINEW_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> frames,
                             counted_children(track, "NUMKEYFRAMES", path, 1, kIntMax, "KEYFRAME", path + "."));
      for (std::size_t k = 0; k < frames.size(); ++k) {
        const XmlElement& frame = el(frames[k]);
        const std::string kpath = element_path(path + ".", "KEYFRAME", k);
        SINEW_RETURN_IF_ERROR(number_attribute(frame, "TIME", kpath));
        const std::vector<std::uint32_t> parts = children(frame);
        std::size_t at = 0;
        SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "TRANSLATION", 3, kpath));
        SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "ROTATION", 4, kpath));
        SINEW_RETURN_IF_ERROR(no_more(parts, at, kpath));
      }
    }
    return {};
  }

  // VERTEXID="a b ..." of `count` ids below `vertices`.
  Status vertex_ids(const XmlElement& e, std::size_t count, std::int64_t vertices, const std::string& path) const {
    const std::string field = path + ".VERTEXID";
    const std::string_view* value = find_attribute(e, "VERTEXID");
    if (value == nullptr) return refuse(ErrorCode::kInvalidData, field, "", "missing attribute");
    std::size_t found = 0;
    for (std::string_view s = trim_blanks(*value); !s.empty(); s = trim_blanks(s)) {
      const std::size_t n = std::min(s.find_first_of(" \t\r\n"), s.size());
      SINEW_RETURN_IF_ERROR(status_of(integer(s.substr(0, n), field, 0, vertices - 1)));
      ++found;
      s.remove_prefix(n);
    }
    if (found != count) {
      return refuse(ErrorCode::kInvalidData, field, *value,
                    std::to_string(found) + " ids where " + std::to_string(count) + " belong");
    }
    return {};
  }

  Status vertex(const XmlElement& v, std::size_t index, std::int64_t vertices, std::int64_t uv_sets, bool springs,
                const std::string& path) const {
    constexpr auto kIntMax = std::numeric_limits<std::int32_t>::max();
    SINEW_ASSIGN_OR_RETURN(const std::int64_t id, int_attribute(v, "ID", path, 0, vertices - 1));
    if (id != static_cast<std::int64_t>(index)) {
      return refuse(ErrorCode::kInvalidData, path + ".ID", std::to_string(id), "vertices must be listed in id order");
    }
    SINEW_ASSIGN_OR_RETURN(const std::int64_t influences, int_attribute(v, "NUMINFLUENCES", path, 0, kIntMax));
    const std::vector<std::uint32_t> parts = children(v);
    std::size_t at = 0;
    SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "POS", 3, path));
    SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "NORM", 3, path));
    if (at < parts.size() && same_name(el(parts[at]).name, "COLLAPSEID")) {
      const std::uint32_t c = parts[at++];
      SINEW_RETURN_IF_ERROR(status_of(integer(el(c).text, path + ".COLLAPSEID", -1, vertices - 1)));
      SINEW_ASSIGN_OR_RETURN(const std::uint32_t n, expect(parts, at, "COLLAPSECOUNT", path));
      SINEW_RETURN_IF_ERROR(status_of(integer(el(n).text, path + ".COLLAPSECOUNT", 0, kIntMax)));
    }
    for (std::int64_t u = 0; u < uv_sets; ++u) SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "TEXCOORD", 2, path));
    for (std::int64_t i = 0; i < influences; ++i) {
      const std::string ipath = path + ".INFLUENCE[" + std::to_string(i) + "]";
      if (at >= parts.size() || !same_name(el(parts[at]).name, "INFLUENCE")) {
        return refuse(ErrorCode::kInvalidData, path + ".NUMINFLUENCES", std::to_string(influences),
                      std::to_string(i) + " <INFLUENCE> elements present");
      }
      const XmlElement& influence = el(parts[at++]);
      // Bone ids past the skeleton are refused after loading, with the mesh.
      SINEW_RETURN_IF_ERROR(status_of(
          int_attribute(influence, "ID", ipath, 0, static_cast<std::int64_t>(anim::kMaxJoints))));
      SINEW_RETURN_IF_ERROR(numbers(influence.text, 1, ipath));
    }
    if (springs) SINEW_RETURN_IF_ERROR(numeric_child(parts, at, "PHYSIQUE", 1, path));
    return no_more(parts, at, path);
  }

  Status mesh(const XmlElement& m) const {
    constexpr auto kIntMax = std::numeric_limits<std::int32_t>::max();
    SINEW_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> submeshes,
                           counted_children(m, "NUMSUBMESH", "MESH", 0, kIntMax, "SUBMESH", ""));
    for (std::size_t s = 0; s < submeshes.size(); ++s) {
      const XmlElement& sub = el(submeshes[s]);
      const std::string path = element_path("", "SUBMESH", s);
      SINEW_ASSIGN_OR_RETURN(const std::int64_t vertices, int_attribute(sub, "NUMVERTICES", path, 0, kIntMax));
      SINEW_ASSIGN_OR_RETURN(const std::int64_t faces, int_attribute(sub, "NUMFACES", path, 0, kIntMax));
      SINEW_RETURN_IF_ERROR(status_of(int_attribute(sub, "MATERIAL", path, -1, kIntMax)));
      SINEW_RETURN_IF_ERROR(status_of(int_attribute(sub, "NUMLODSTEPS", path, 0, kIntMax)));
      SINEW_ASSIGN_OR_RETURN(const std::int64_t springs, int_attribute(sub, "NUMSPRINGS", path, 0, kIntMax));
      // Cal3D keeps at most a handful of texture coordinate sets.
      SINEW_ASSIGN_OR_RETURN(const std::int64_t uv_sets, int_attribute(sub, "NUMTEXCOORDS", path, 0, 16));
      const std::vector<std::uint32_t> parts = children(sub);
      std::size_t at = 0;
      std::int64_t seen_vertices = 0, seen_springs = 0, seen_faces = 0;
      for (; at < parts.size() && same_name(el(parts[at]).name, "VERTEX"); ++at, ++seen_vertices) {
        if (seen_vertices == vertices) break;
        SINEW_RETURN_IF_ERROR(vertex(el(parts[at]), static_cast<std::size_t>(seen_vertices), vertices,
                                     uv_sets, springs > 0, path + ".VERTEX[" + std::to_string(seen_vertices) + "]"));
      }
      SINEW_RETURN_IF_ERROR(count_matches(vertices, static_cast<std::size_t>(seen_vertices), path + ".NUMVERTICES"));
      for (; at < parts.size() && same_name(el(parts[at]).name, "SPRING") && seen_springs < springs;
           ++at, ++seen_springs) {
        const std::string spath = path + ".SPRING[" + std::to_string(seen_springs) + "]";
        SINEW_RETURN_IF_ERROR(vertex_ids(el(parts[at]), 2, vertices, spath));
        SINEW_RETURN_IF_ERROR(number_attribute(el(parts[at]), "COEF", spath));
        SINEW_RETURN_IF_ERROR(number_attribute(el(parts[at]), "LENGTH", spath));
      }
      SINEW_RETURN_IF_ERROR(count_matches(springs, static_cast<std::size_t>(seen_springs), path + ".NUMSPRINGS"));
      for (; at < parts.size() && same_name(el(parts[at]).name, "FACE") && seen_faces < faces; ++at, ++seen_faces) {
        SINEW_RETURN_IF_ERROR(
            vertex_ids(el(parts[at]), 3, vertices, path + ".FACE[" + std::to_string(seen_faces) + "]"));
      }
      SINEW_RETURN_IF_ERROR(count_matches(faces, static_cast<std::size_t>(seen_faces), path + ".NUMFACES"));
      SINEW_RETURN_IF_ERROR(no_more(parts, at, path));
    }
    return {};
  }

  const XmlTree& tree_;
  const std::string& file_;
};

}  // namespace

Status check_cal3d_xml(std::string_view text, const std::string& file, Cal3dXmlKind kind) {
  SINEW_ASSIGN_OR_RETURN(const XmlTree tree, parse_xml_tree(text, file));
  return Checker(tree, file).check(kind);
}

}  // namespace sinew::editor::cal3d_detail
