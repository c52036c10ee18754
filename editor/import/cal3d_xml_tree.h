// A flat, bounded reading of an XML file for the checks of Cal3D's XML
// formats (cal3d_xml_check.h). Separate from those checks because it knows
// XML's syntax and nothing of Cal3D: elements, attributes and text, read
// without recursion, with nesting, element count and stray syntax refused
// before anything deeper looks at the file.
//
// Views point into the caller's text, which must outlive the tree. Entities
// are left as written: the checks that read values only accept numbers, and
// names are passed on to Cal3D untouched.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

// Cal3D's XML parser recurses once per level and overflows the stack at some
// tens of thousands of levels; its formats need four (MESH > SUBMESH > VERTEX
// > INFLUENCE). Anything deeper than this is refused before Cal3D sees it.
inline constexpr std::size_t kMaxXmlDepth = 16;
// Far beyond any character file (a 100,000-vertex mesh has about a million
// elements); bounds the tree's memory whatever the file holds.
inline constexpr std::size_t kMaxXmlElements = 4u << 20;

inline constexpr std::uint32_t kNoElement = 0xffffffffu;

struct XmlElement {
  std::string_view name;
  std::vector<std::pair<std::string_view, std::string_view>> attributes;
  std::string_view text;          // the element's text, blanks trimmed (empty if none)
  std::uint32_t first_child = kNoElement;
  std::uint32_t next_sibling = kNoElement;
  std::size_t line = 0;           // where the start tag is, for messages
};

struct XmlTree {
  std::vector<XmlElement> elements;
  std::uint32_t first_root = kNoElement;  // top-level elements are siblings from here
};

// The tree of `text`, or an error naming `file`, the element (or "xml") and
// the line: unclosed or mismatched tags, text outside elements, DOCTYPE and
// CDATA sections, nesting past kMaxXmlDepth, more than kMaxXmlElements.
Expected<XmlTree> parse_xml_tree(std::string_view text, const std::string& file);

// Case-insensitive, as Cal3D compares names.
bool same_name(std::string_view a, std::string_view b);

// The attribute's value, or nullptr when `e` has none of that name.
const std::string_view* find_attribute(const XmlElement& e, std::string_view name);

}  // namespace sinew::editor::cal3d_detail
