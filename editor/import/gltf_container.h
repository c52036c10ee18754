// The bytes of a .gltf or .glb file, checked before tinygltf parses them:
// its JSON parser recurses once per nesting level and overflows the stack
// on documents nested some ten thousand levels deep, so nesting is bounded
// by a scan of the bytes first (runtime/io/json_nesting.h); a .glb's header
// must describe the file exactly (no data past its declared length).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/io/json_nesting.h"

namespace sinew::editor {

// Deeper JSON nesting is refused. glTF itself nests a few levels; the
// limit leaves ample room for extras.
inline constexpr std::size_t kMaxJsonNesting = 256;

// The chunks of a .glb that Sinew reads: the JSON, and the BIN chunk when
// the file has one (empty otherwise).
struct GlbChunks {
  std::string_view json;
  std::optional<std::string_view> bin;
};

// A whole .glb file: the 12-byte header's magic, version and length (equal
// to the file's size), the first chunk being JSON, every chunk's header and
// length inside the file (tinygltf trusted a BIN chunk's length and read
// past the input), a BIN chunk only second, and the JSON's nesting.
Expected<GlbChunks> check_glb(std::string_view bytes, const std::string& file);

// Where external buffer and image files may be read from: the asset's own
// folder, plus `extra` folders the user allows. Paths are compared after
// resolving "..", "." and symbolic links.
class AssetRoots {
 public:
  AssetRoots(const std::string& asset_file, const std::vector<std::string>& extra);
  // The folder (resolved) holding `path` when it is inside a root, else empty.
  std::filesystem::path root_of(const std::filesystem::path& path) const;
  const std::filesystem::path& asset_folder() const { return roots_.front(); }

 private:
  std::vector<std::filesystem::path> roots_;  // resolved; the asset's folder first
};

// The glTF JSON's checks that need the document, done before tinygltf reads
// it (a document that is not JSON passes, for tinygltf to report):
// - extensionsRequired lists only extensions that change nothing Sinew
//   reads (materials, textures, lights);
// - every index (glTFid) is an integer in [0, 2^31 - 1]: tinygltf keeps ids
//   in int, so larger ones wrap and negative ones read as "absent";
// - every buffers[i].uri and images[i].uri that is not a data: URI,
//   percent-decoded as tinygltf decodes it, is a relative reference
//   resolving inside `roots`: absolute paths, other schemes and ".."
//   escapes are refused (tinygltf's own reads are guarded too: it also
//   looks in the current directory).
// - in a .glb (`glb` given; nullptr for a .gltf), buffers[0] without a uri
//   is the BIN chunk, which must exist, and its byteLength may not pass the
//   chunk's end; other buffers need a uri.
// Each error names the field and the value.
Status check_gltf_document(std::string_view json, const std::string& file, const AssetRoots& roots,
                           const GlbChunks* glb = nullptr);

// RFC 3986 percent-decoding ("%2e%2E" -> ".."); false for a malformed escape.
bool percent_decode(std::string_view uri, std::string& out);

}  // namespace sinew::editor
