// The bytes of a .gltf or .glb file, checked before tinygltf parses them:
// its JSON parser recurses once per nesting level and overflows the stack
// on documents nested some ten thousand levels deep, so nesting is bounded
// by a scan of the bytes first; a .glb's header must describe the file
// exactly (no data past its declared length).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "runtime/core/expected.h"

namespace sinew::editor {

// Deeper JSON nesting is refused. glTF itself nests a few levels; the
// limit leaves ample room for extras.
inline constexpr std::size_t kMaxJsonNesting = 256;

// OK when no array or object in `json` (outside strings) is nested more
// than `max_depth` deep; otherwise names `file`, `field` and the byte offset.
Status check_json_nesting(std::string_view json, std::size_t max_depth, const std::string& file,
                          const std::string& field);

// A whole .glb file: the 12-byte header's magic, version and length (equal
// to the file's size), the first chunk being JSON inside the file, and its
// JSON's nesting. Returns the JSON chunk.
Expected<std::string_view> check_glb(std::string_view bytes, const std::string& file);

}  // namespace sinew::editor
