// Text from a file or the command line as the editor's JSON and terminal
// output take it: bytes of invalid UTF-8 (a path may hold any) and control
// bytes (which a terminal would obey) become \xHH, valid UTF-8 stays, and
// nothing is cut (printable() without its length bound). nlohmann's dump()
// refuses invalid UTF-8 outright, so every string of a file name, clip,
// bone or source name goes through this before it enters a JSON document.
#pragma once

#include <string>
#include <string_view>

#include "runtime/core/status.h"

namespace sinew::editor {

inline std::string shown(std::string_view text) { return printable(text, std::string_view::npos); }

}  // namespace sinew::editor
