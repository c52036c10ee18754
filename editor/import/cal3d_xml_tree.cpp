// The bounded XML reading (cal3d_xml_tree.h): one pass over the text with an
// explicit stack of open elements, so depth costs no native stack.
#include "editor/import/cal3d_xml_tree.h"

#include <algorithm>

namespace sinew::editor::cal3d_detail {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

bool is_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.' || c == ':';
}

// Names in messages are cut: an element name is as long as the file makes it.
std::string_view shown(std::string_view name) { return name.substr(0, 40); }

std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

class Reader {
 public:
  Reader(std::string_view text, const std::string& file) : text_(text), file_(file) {}

  Expected<XmlTree> read() {
    std::vector<std::uint32_t> open;      // the elements whose end tag is still to come
    std::vector<std::uint32_t> last_child;  // per open element, and one for the top level
    last_child.push_back(kNoElement);
    // XML allows a leading UTF-8 byte-order mark, but Cal3D's parser fails
    // on one with a bare "invalid file format": say what it is instead.
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") {
      return refuse("xml", "a UTF-8 byte-order mark, which Cal3D's XML parser cannot read (save without it)");
    }
    while (pos_ < text_.size()) {
      if (text_[pos_] != '<') {
        const std::size_t end = std::min(text_.find('<', pos_), text_.size());
        const std::string_view segment = trim_blanks(text_.substr(pos_, end - pos_));
        if (!segment.empty()) {
          if (open.empty()) return refuse("xml", "text outside any element");
          XmlElement& e = tree_.elements[open.back()];
          if (!e.text.empty()) return refuse(e.name, "text in more than one place inside the element");
          e.text = segment;
        }
        advance_to(end);
        continue;
      }
      const std::string_view rest = text_.substr(pos_);
      if (rest.substr(0, 4) == "<!--") {
        SINEW_RETURN_IF_ERROR(skip_past("-->", "comment"));
      } else if (rest.substr(0, 2) == "<?") {
        SINEW_RETURN_IF_ERROR(skip_past("?>", "declaration"));
      } else if (rest.substr(0, 2) == "<!") {
        return refuse("xml", "DOCTYPE and CDATA sections are not part of Cal3D's formats");
      } else if (rest.substr(0, 2) == "</") {
        advance_to(pos_ + 2);
        const std::string_view name = read_name();
        skip_blanks();
        if (open.empty() || name != tree_.elements[open.back()].name || !at('>')) {
          return refuse(name.empty() ? std::string_view("xml") : name,
                        open.empty() ? "end tag without a start tag" : "end tag does not match the open element");
        }
        advance_to(pos_ + 1);
        open.pop_back();
        last_child.pop_back();
      } else {
        SINEW_RETURN_IF_ERROR(start_tag(open, last_child));
      }
    }
    if (!open.empty()) {
      return make_error(ErrorCode::kTruncated, file_, shown(tree_.elements[open.back()].name),
                        "line " + std::to_string(line_), "the file ends before the element is closed");
    }
    return std::move(tree_);
  }

 private:
  bool at(char c) const { return pos_ < text_.size() && text_[pos_] == c; }

  void advance_to(std::size_t to) {
    line_ += static_cast<std::size_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(pos_),
                                                 text_.begin() + static_cast<std::ptrdiff_t>(to), '\n'));
    pos_ = to;
  }
  void skip_blanks() {
    std::size_t to = pos_;
    while (to < text_.size() && is_blank(text_[to])) ++to;
    advance_to(to);
  }
  std::string_view read_name() {
    const std::size_t from = pos_;
    while (pos_ < text_.size() && is_name_char(text_[pos_])) ++pos_;
    return text_.substr(from, pos_ - from);
  }
  Status skip_past(std::string_view end, std::string_view what) {
    const std::size_t at_end = text_.find(end, pos_ + 2);
    if (at_end == std::string_view::npos) {
      return make_error(ErrorCode::kTruncated, file_, "xml", "line " + std::to_string(line_),
                        "the file ends inside a " + std::string(what));
    }
    advance_to(at_end + end.size());
    return {};
  }
  Status refuse(std::string_view element, std::string_view detail) const {
    return make_error(ErrorCode::kInvalidData, file_, shown(element), "line " + std::to_string(line_),
                      std::string(detail));
  }

  Status start_tag(std::vector<std::uint32_t>& open, std::vector<std::uint32_t>& last_child) {
    advance_to(pos_ + 1);
    XmlElement e;
    e.line = line_;
    e.name = read_name();
    if (e.name.empty()) return refuse("xml", "'<' not followed by an element name");
    if (open.size() >= kMaxXmlDepth) {
      return make_error(ErrorCode::kLimitExceeded, file_, shown(e.name), "line " + std::to_string(line_),
                        "elements nested deeper than " + std::to_string(kMaxXmlDepth) +
                            " levels (Cal3D's formats need 4)");
    }
    if (tree_.elements.size() >= kMaxXmlElements) {
      return make_error(ErrorCode::kLimitExceeded, file_, shown(e.name), "line " + std::to_string(line_),
                        "more than " + std::to_string(kMaxXmlElements) + " elements");
    }
    bool closed = false;
    for (;;) {
      const std::size_t before = pos_;
      skip_blanks();
      if (at('>')) break;
      if (text_.substr(pos_, 2) == "/>") {
        closed = true;
        advance_to(pos_ + 1);
        break;
      }
      if (pos_ == before) return refuse(e.name, "expected a blank before the attribute");
      const std::string_view name = read_name();
      skip_blanks();
      if (name.empty() || !at('=')) return refuse(e.name, "malformed attribute");
      advance_to(pos_ + 1);
      skip_blanks();
      if (!at('"') && !at('\'')) return refuse(e.name, "attribute " + std::string(shown(name)) + " without a quoted value");
      const char quote = text_[pos_];
      const std::size_t close = text_.find(quote, pos_ + 1);
      if (close == std::string_view::npos) return refuse(e.name, "unterminated attribute " + std::string(shown(name)));
      const std::string_view value = text_.substr(pos_ + 1, close - pos_ - 1);
      if (value.find('<') != std::string_view::npos) return refuse(e.name, "'<' inside attribute " + std::string(shown(name)));
      if (find_attribute(e, name) != nullptr) return refuse(e.name, "attribute " + std::string(shown(name)) + " given twice");
      e.attributes.emplace_back(name, value);
      advance_to(close + 1);
    }
    advance_to(pos_ + 1);  // past '>'

    const auto index = static_cast<std::uint32_t>(tree_.elements.size());
    tree_.elements.push_back(std::move(e));
    // Link it after its previous sibling, or as the first child or root.
    std::uint32_t& previous = last_child.back();
    if (previous != kNoElement) {
      tree_.elements[previous].next_sibling = index;
    } else if (open.empty()) {
      tree_.first_root = index;
    } else {
      tree_.elements[open.back()].first_child = index;
    }
    previous = index;
    if (!closed) {
      open.push_back(index);
      last_child.push_back(kNoElement);
    }
    return {};
  }

  std::string_view text_;
  const std::string& file_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  XmlTree tree_;
};

}  // namespace

bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto up = [](char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; };
    if (up(a[i]) != up(b[i])) return false;
  }
  return true;
}

const std::string_view* find_attribute(const XmlElement& e, std::string_view name) {
  for (const auto& [key, value] : e.attributes) {
    if (same_name(key, name)) return &value;
  }
  return nullptr;
}

Expected<XmlTree> parse_xml_tree(std::string_view text, const std::string& file) {
  return Reader(text, file).read();
}

}  // namespace sinew::editor::cal3d_detail
