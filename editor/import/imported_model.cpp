#include "editor/import/imported_model.h"

#include <charconv>

namespace sinew::editor {

const anim::Clip* ImportedModel::find_clip(const std::string& name) const {
  if (!name.empty() && name[0] == '#') {
    std::size_t index = 0;
    const char* first = name.data() + 1;
    const char* last = name.data() + name.size();
    const auto [end, ec] = std::from_chars(first, last, index);
    if (ec != std::errc() || end != last || index >= clips.size()) return nullptr;
    return &clips[index];
  }
  for (const anim::Clip& c : clips) {
    if (c.name() == name) return &c;
  }
  return nullptr;
}

}  // namespace sinew::editor
