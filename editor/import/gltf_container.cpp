#include "editor/import/gltf_container.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <system_error>

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

namespace {

std::filesystem::path resolved(const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::path r = std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
  if (ec) return std::filesystem::absolute(p, ec).lexically_normal();
  return r;
}

bool inside(const std::filesystem::path& path, const std::filesystem::path& root) {
  const auto rel = path.lexically_relative(root);
  return !rel.empty() && *rel.begin() != "..";
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// A scheme ("http:", "file:", "C:") before any '/'.
bool has_scheme(std::string_view uri) {
  const std::size_t colon = uri.find(':');
  if (colon == std::string_view::npos || colon == 0) return false;
  const std::size_t slash = uri.find('/');
  if (slash != std::string_view::npos && slash < colon) return false;
  if (!std::isalpha(static_cast<unsigned char>(uri[0]))) return false;
  for (std::size_t i = 1; i < colon; ++i) {
    const unsigned char c = static_cast<unsigned char>(uri[i]);
    if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return false;
  }
  return true;
}

}  // namespace

AssetRoots::AssetRoots(const std::string& asset_file, const std::vector<std::string>& extra) {
  roots_.push_back(resolved(std::filesystem::path(asset_file).parent_path().empty()
                                ? std::filesystem::path(".")
                                : std::filesystem::path(asset_file).parent_path()));
  for (const std::string& e : extra) roots_.push_back(resolved(e));
}

std::filesystem::path AssetRoots::root_of(const std::filesystem::path& path) const {
  const std::filesystem::path p = resolved(path);
  for (const std::filesystem::path& root : roots_) {
    if (inside(p, root)) return root;
  }
  return {};
}

bool percent_decode(std::string_view uri, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      out += uri[i];
      continue;
    }
    if (i + 2 >= uri.size()) return false;
    const int hi = hex_value(uri[i + 1]), lo = hex_value(uri[i + 2]);
    if (hi < 0 || lo < 0) return false;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return true;
}

Status check_external_uris(std::string_view json, const std::string& file, const AssetRoots& roots) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const std::exception&) {
    return {};  // not JSON: tinygltf reports it, with its own message
  }
  if (!doc.is_object()) return {};
  for (const char* array : {"buffers", "images"}) {
    const auto it = doc.find(array);
    if (it == doc.end() || !it->is_array()) continue;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& entry = (*it)[i];
      if (!entry.is_object()) continue;
      const auto uri_it = entry.find("uri");
      if (uri_it == entry.end() || !uri_it->is_string()) continue;
      const std::string& uri = uri_it->get_ref<const std::string&>();
      if (uri.rfind("data:", 0) == 0) continue;
      const std::string field = std::string(array) + "[" + std::to_string(i) + "].uri";
      std::string decoded;
      if (!percent_decode(uri, decoded)) {
        return make_error(ErrorCode::kInvalidData, file, field, uri, "a malformed percent escape");
      }
      if (decoded.find('\0') != std::string::npos) {
        return make_error(ErrorCode::kInvalidData, file, field, uri, "a NUL byte in the file name");
      }
      if (!decoded.empty() && (decoded[0] == '/' || decoded[0] == '\\')) {
        return make_error(ErrorCode::kInvalidData, file, field, uri,
                          "absolute paths are not allowed (a glTF file names its files relative to itself)");
      }
      if (has_scheme(decoded)) {
        return make_error(ErrorCode::kInvalidData, file, field, uri,
                          "only relative file names and data: URIs are supported");
      }
      const std::filesystem::path target = roots.asset_folder() / decoded;
      if (roots.root_of(target).empty()) {
        return make_error(ErrorCode::kInvalidData, file, field, uri,
                          "resolves to " + resolved(target).string() + ", outside the asset's folder " +
                              roots.asset_folder().string() + " (allow more folders with --asset-roots)");
      }
    }
  }
  return {};
}

}  // namespace sinew::editor
