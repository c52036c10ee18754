// How deep a JSON text nests, found by a scan of its bytes before any
// parser sees it. Parsers that recurse once per level (tinygltf's) overflow
// the stack some ten thousand levels down, and a value nested that deep
// has no business in any file Sinew reads; every reader of JSON from a
// file bounds it first (glTF 256 levels, scene recipes 16, joint limits 16).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "runtime/core/status.h"

namespace sinew {

// OK when no array or object in `json` (outside strings) is nested more
// than `max_depth` deep; otherwise kLimitExceeded naming `file`, `field`
// and the byte offset where the limit was passed.
Status check_json_nesting(std::string_view json, std::size_t max_depth, const std::string& file,
                          const std::string& field);

}  // namespace sinew
