#include "editor/import/gltf_container.h"

#include <cctype>
#include <climits>
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

Expected<GlbChunks> check_glb(std::string_view bytes, const std::string& file) {
  constexpr std::size_t kHeader = 12, kChunkHeader = 8;
  constexpr std::uint32_t kJsonChunk = 0x4E4F534Au;  // "JSON"
  constexpr std::uint32_t kBinChunk = 0x004E4942u;   // "BIN\0"
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
  GlbChunks chunks;
  // Every chunk: an 8-byte header, then as many bytes as it claims, all
  // inside the file (tinygltf takes the BIN chunk's length on trust).
  std::size_t at = kHeader;
  for (std::size_t index = 0; at < bytes.size(); ++index) {
    const std::string field = "glb.chunks[" + std::to_string(index) + "]";
    const std::size_t left = bytes.size() - at;
    if (left < kChunkHeader) {
      return make_error(ErrorCode::kTruncated, file, field, std::to_string(left) + " bytes left",
                        "a chunk header needs 8 bytes");
    }
    const std::uint32_t chunk_length = read_u32(bytes, at);
    const std::uint32_t type = read_u32(bytes, at + 4);
    if (chunk_length > left - kChunkHeader) {
      return make_error(ErrorCode::kTruncated, file, field + ".length", std::to_string(chunk_length),
                        "past the end of the file (" + std::to_string(left - kChunkHeader) + " bytes left)");
    }
    const std::string_view data = bytes.substr(at + kChunkHeader, chunk_length);
    if (index == 0) {
      if (type != kJsonChunk) {
        return make_error(ErrorCode::kInvalidData, file, field + ".type", std::to_string(type),
                          "the first chunk must be JSON");
      }
      chunks.json = data;
    } else if (type == kBinChunk) {
      if (index != 1) {
        return make_error(ErrorCode::kInvalidData, file, field + ".type", "BIN",
                          "a BIN chunk may only be the second chunk");
      }
      chunks.bin = data;
    }
    at += kChunkHeader + chunk_length;
  }
  SINEW_RETURN_IF_ERROR(check_json_nesting(chunks.json, kMaxJsonNesting, file, "glb.chunks[0]"));
  return chunks;
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

namespace {

Status check_uris(const nlohmann::json& doc, const std::string& file, const AssetRoots& roots) {
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


// In a .glb, a buffer without a uri is the BIN chunk: only buffers[0] may
// be, the chunk must exist, and the buffer may not claim more bytes than the
// chunk holds (tinygltf copied byteLength bytes from it, reading past the
// input). A byteLength that is not a count is left to tinygltf to refuse.
Status check_glb_buffers(const nlohmann::json& doc, const std::string& file, const GlbChunks& glb) {
  const auto it = doc.find("buffers");
  if (it == doc.end() || !it->is_array()) return {};
  for (std::size_t i = 0; i < it->size(); ++i) {
    const nlohmann::json& buffer = (*it)[i];
    if (!buffer.is_object() || buffer.contains("uri")) continue;
    const std::string field = "buffers[" + std::to_string(i) + "]";
    if (i != 0) {
      return make_error(ErrorCode::kInvalidData, file, field + ".uri", "(none)",
                        "only buffers[0] can be the .glb's BIN chunk; other buffers need a uri");
    }
    if (!glb.bin) {
      return make_error(ErrorCode::kInvalidData, file, field + ".uri", "(none)",
                        "the buffer is the .glb's BIN chunk, and the file has none");
    }
    const auto length = buffer.find("byteLength");
    if (length == buffer.end() || !length->is_number_unsigned()) continue;
    const std::uint64_t claimed = length->get<std::uint64_t>();
    if (claimed > glb.bin->size()) {
      return make_error(ErrorCode::kTruncated, file, field + ".byteLength", std::to_string(claimed),
                        "more than the BIN chunk's " + std::to_string(glb.bin->size()) + " bytes");
    }
  }
  return {};
}

// Index-valued properties of glTF 2.0 (the spec's "glTFid"s), by where they
// sit: "a.b[]" is an array of ids, "a[].b" a property of each element.
// tinygltf reads them as int, so 4294967297 would become 1 and a negative
// id would read as "absent".
Status check_id(const nlohmann::json& v, const std::string& file, const std::string& field) {
  if (v.is_number_unsigned() && v.get<std::uint64_t>() <= static_cast<std::uint64_t>(INT32_MAX)) return {};
  if (v.is_number_integer() && !v.is_number_unsigned()) {
    return make_error(ErrorCode::kInvalidData, file, field, v.dump(), "a negative index");
  }
  if (v.is_number_unsigned()) {
    return make_error(ErrorCode::kOutOfBounds, file, field, v.dump(), "an index past 2^31 - 1");
  }
  return make_error(ErrorCode::kInvalidData, file, field, v.dump().substr(0, 40), "an index must be an integer");
}

// The ids at `path` (dot-separated; "[]" after a name walks an array) below `v`.
Status check_ids_at(const nlohmann::json& v, std::string_view path, const std::string& file,
                    const std::string& field) {
  if (path.empty()) return check_id(v, file, field);
  const std::size_t dot = path.find('.');
  std::string_view step = path.substr(0, dot);
  const std::string_view rest = dot == std::string_view::npos ? std::string_view() : path.substr(dot + 1);
  const bool each = step.size() > 2 && step.substr(step.size() - 2) == "[]";
  if (each) step.remove_suffix(2);
  if (!v.is_object()) return {};
  const auto it = v.find(std::string(step));
  if (it == v.end()) return {};
  const std::string here = field.empty() ? std::string(step) : field + "." + std::string(step);
  if (!each) return check_ids_at(*it, rest, file, here);
  if (!it->is_array()) return {};  // tinygltf reports the wrong type
  for (std::size_t i = 0; i < it->size(); ++i) {
    SINEW_RETURN_IF_ERROR(check_ids_at((*it)[i], rest, file, here + "[" + std::to_string(i) + "]"));
  }
  return {};
}

Status check_ids(const nlohmann::json& doc, const std::string& file) {
  static constexpr std::string_view kIdPaths[] = {
      "scene",
      "scenes[].nodes[]",
      "nodes[].children[]",
      "nodes[].mesh",
      "nodes[].skin",
      "nodes[].camera",
      "skins[].joints[]",
      "skins[].skeleton",
      "skins[].inverseBindMatrices",
      "meshes[].primitives[].indices",
      "meshes[].primitives[].material",
      "accessors[].bufferView",
      "accessors[].sparse.indices.bufferView",
      "accessors[].sparse.values.bufferView",
      "bufferViews[].buffer",
      "animations[].channels[].sampler",
      "animations[].channels[].target.node",
      "animations[].samplers[].input",
      "animations[].samplers[].output",
      "textures[].source",
      "textures[].sampler",
      "images[].bufferView",
  };
  for (const std::string_view path : kIdPaths) SINEW_RETURN_IF_ERROR(check_ids_at(doc, path, file, ""));
  // Attribute and morph-target accessors: every value of those objects.
  const auto meshes = doc.find("meshes");
  if (meshes == doc.end() || !meshes->is_array()) return {};
  for (std::size_t m = 0; m < meshes->size(); ++m) {
    const auto prims = (*meshes)[m].is_object() ? (*meshes)[m].find("primitives") : (*meshes)[m].end();
    if (!(*meshes)[m].is_object() || prims == (*meshes)[m].end() || !prims->is_array()) continue;
    for (std::size_t p = 0; p < prims->size(); ++p) {
      const nlohmann::json& prim = (*prims)[p];
      if (!prim.is_object()) continue;
      const std::string at = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
      const auto attributes = prim.find("attributes");
      if (attributes != prim.end() && attributes->is_object()) {
        for (const auto& [name, id] : attributes->items()) {
          SINEW_RETURN_IF_ERROR(check_id(id, file, at + ".attributes." + name));
        }
      }
      const auto targets = prim.find("targets");
      if (targets == prim.end() || !targets->is_array()) continue;
      for (std::size_t t = 0; t < targets->size(); ++t) {
        if (!(*targets)[t].is_object()) continue;
        for (const auto& [name, id] : (*targets)[t].items()) {
          SINEW_RETURN_IF_ERROR(check_id(id, file, at + ".targets[" + std::to_string(t) + "]." + name));
        }
      }
    }
  }
  return {};
}

// Extensions a file may require: ones that only change materials or
// textures, which Sinew does not read. Any other (mesh compression,
// quantized attributes, ...) would change the geometry we decode.
bool ignorable_required_extension(const std::string& name) {
  return name.rfind("KHR_materials_", 0) == 0 || name == "KHR_texture_transform" || name == "KHR_texture_basisu" ||
         name == "EXT_texture_webp" || name == "KHR_lights_punctual";
}

Status check_required_extensions(const nlohmann::json& doc, const std::string& file) {
  const auto it = doc.find("extensionsRequired");
  if (it == doc.end() || !it->is_array()) return {};
  for (std::size_t i = 0; i < it->size(); ++i) {
    const nlohmann::json& e = (*it)[i];
    const std::string name = e.is_string() ? e.get<std::string>() : e.dump();
    if (!e.is_string() || !ignorable_required_extension(name)) {
      return make_error(ErrorCode::kUnsupportedVersion, file, "extensionsRequired[" + std::to_string(i) + "]",
                        name.substr(0, 80), "a required extension this importer does not support");
    }
  }
  return {};
}

}  // namespace

Status check_gltf_document(std::string_view json, const std::string& file, const AssetRoots& roots,
                           const GlbChunks* glb) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const std::exception&) {
    return {};  // not JSON: tinygltf reports it, with its own message
  }
  if (!doc.is_object()) return {};
  SINEW_RETURN_IF_ERROR(check_required_extensions(doc, file));
  SINEW_RETURN_IF_ERROR(check_ids(doc, file));
  if (glb != nullptr) SINEW_RETURN_IF_ERROR(check_glb_buffers(doc, file, *glb));
  return check_uris(doc, file, roots);
}

}  // namespace sinew::editor
