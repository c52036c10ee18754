#include "editor/import/gltf_container.h"

#include <cstdint>
#include <cstring>

namespace sinew::editor {
namespace {

std::uint32_t read_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, sizeof v);  // glb is little-endian, as are the targets
  return v;
}

}  // namespace

Status check_json_nesting(std::string_view json, std::size_t max_depth, const std::string& file,
                          const std::string& field) {
  std::size_t depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        return make_error(ErrorCode::kLimitExceeded, file, field, "byte " + std::to_string(i),
                          "JSON nested deeper than " + std::to_string(max_depth) + " levels (the limit)");
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;  // unbalanced closers are the parser's to report
    }
  }
  return {};
}

Expected<std::string_view> check_glb(std::string_view bytes, const std::string& file) {
  constexpr std::size_t kHeader = 12, kChunkHeader = 8;
  constexpr std::uint32_t kJsonChunk = 0x4E4F534Au;  // "JSON"
  if (bytes.size() < kHeader + kChunkHeader) {
    return make_error(ErrorCode::kTruncated, file, "glb.header", std::to_string(bytes.size()) + " bytes",
                      "shorter than the 20-byte header and first chunk header");
  }
  const std::uint32_t version = read_u32(bytes, 4);
  if (version != 2) {
    return make_error(ErrorCode::kUnsupportedVersion, file, "glb.header.version", std::to_string(version),
                      version == 1 ? "glTF 1.0 binary files are not supported (glTF 2.0 only)"
                                   : "only glTF 2.0 (version 2) is supported");
  }
  const std::uint32_t length = read_u32(bytes, 8);
  if (length != bytes.size()) {
    return make_error(ErrorCode::kInvalidData, file, "glb.header.length", std::to_string(length),
                      "the file has " + std::to_string(bytes.size()) + " bytes" +
                          (length < bytes.size() ? " (data past the declared end)" : ""));
  }
  const std::uint32_t json_length = read_u32(bytes, 12);
  const std::uint32_t type = read_u32(bytes, 16);
  if (type != kJsonChunk) {
    return make_error(ErrorCode::kInvalidData, file, "glb.chunks[0].type", std::to_string(type),
                      "the first chunk must be JSON");
  }
  if (json_length > bytes.size() - kHeader - kChunkHeader) {
    return make_error(ErrorCode::kTruncated, file, "glb.chunks[0].length", std::to_string(json_length),
                      "past the end of the file");
  }
  const std::string_view json = bytes.substr(kHeader + kChunkHeader, json_length);
  SINEW_RETURN_IF_ERROR(check_json_nesting(json, kMaxJsonNesting, file, "glb.chunks[0]"));
  return json;
}

}  // namespace sinew::editor
