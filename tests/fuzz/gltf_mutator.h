// Structure-aware mutations of a glTF document for the glTF fuzzer
// (gltf_import_fuzz.cpp). Byte mutations almost never keep JSON well formed,
// so they rarely reach the importer's graph, limit and index checks; these
// mutate the parsed document and write it back (.gltf text, or .glb with its
// BIN chunk kept): duplicate, repeat, delete and swap elements of the
// top-level arrays, renumber and retarget index fields, chain and loop
// nodes, nest extras deeply, and set counts, offsets and enums to edge
// values. The classes of hostile input in docs/ROBUSTNESS.md ("Hostile
// input") are what it aims at.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace sinew::fuzz {

namespace gltf_mutation {

using Json = nlohmann::json;

// The arrays whose elements other parts refer to by index.
inline constexpr const char* kArrays[] = {"nodes",    "meshes", "accessors", "bufferViews", "buffers",
                                          "skins",    "animations", "materials", "scenes"};
// Fields holding one index, and fields holding arrays of them.
inline constexpr const char* kIndexFields[] = {"mesh",  "skin",   "bufferView", "indices", "POSITION",
                                               "NORMAL", "JOINTS_0", "WEIGHTS_0", "input", "output",
                                               "node",  "sampler", "inverseBindMatrices", "skeleton",
                                               "buffer", "scene",  "material"};
inline constexpr const char* kIndexArrays[] = {"children", "joints", "nodes"};

// Every object and array in the document, for picking one at random.
inline void collect(Json& j, std::vector<Json*>& out, int depth = 0) {
  if (depth > 64 || !(j.is_object() || j.is_array())) return;
  out.push_back(&j);
  for (Json& child : j) collect(child, out, depth + 1);
}

inline std::int64_t edge_index(std::mt19937& g, std::int64_t n) {
  switch (g() % 7) {
    case 0: return -1;
    case 1: return n;                      // one past the end
    case 2: return std::int64_t{1} << 31;  // past glTFid's range
    case 3: return (std::int64_t{1} << 32) + 1;  // wraps to 1 in 32 bits
    case 4: return 0;
    default: return n > 0 ? static_cast<std::int64_t>(g() % static_cast<std::uint32_t>(n)) : 0;
  }
}

inline std::int64_t array_size(const Json& doc, const char* name) {
  const auto it = doc.find(name);
  return it != doc.end() && it->is_array() ? static_cast<std::int64_t>(it->size()) : 0;
}

// One structural mutation of `doc` (a parsed glTF object). Returns false
// when the picked mutation found nothing to act on.
inline bool mutate(Json& doc, std::mt19937& g) {
  const char* array = kArrays[g() % std::size(kArrays)];
  Json* elements = doc.contains(array) && doc[array].is_array() ? &doc[array] : nullptr;
  const std::size_t n = elements ? elements->size() : 0;
  switch (g() % 10) {
    case 0: {  // duplicate one element, or repeat it many times
      if (n == 0) return false;
      const Json copy = (*elements)[g() % n];
      const std::size_t times = g() % 4 == 0 ? 1 + g() % 2000 : 1;
      for (std::size_t i = 0; i < times; ++i) elements->push_back(copy);
      return true;
    }
    case 1: {  // delete one (everything after it is renumbered by one)
      if (n == 0) return false;
      elements->erase(elements->begin() + static_cast<std::ptrdiff_t>(g() % n));
      return true;
    }
    case 2: {  // swap two: references now point at the other one
      if (n < 2) return false;
      std::swap((*elements)[g() % n], (*elements)[g() % n]);
      return true;
    }
    case 3:
    case 4: {  // renumber or retarget one index field anywhere
      std::vector<Json*> all;
      collect(doc, all);
      std::vector<Json*> fields;
      for (Json* j : all) {
        if (!j->is_object()) continue;
        for (const char* f : kIndexFields) {
          if (j->contains(f) && (*j)[f].is_number_integer()) fields.push_back(&(*j)[f]);
        }
        for (const char* f : kIndexArrays) {
          if (!j->contains(f) || !(*j)[f].is_array()) continue;
          for (Json& e : (*j)[f]) {
            if (e.is_number_integer()) fields.push_back(&e);
          }
        }
      }
      if (fields.empty()) return false;
      *fields[g() % fields.size()] = edge_index(g, array_size(doc, "nodes") + array_size(doc, "accessors"));
      return true;
    }
    case 5: {  // chain nodes (a long parent chain), perhaps closing a loop
      const std::int64_t nodes = array_size(doc, "nodes");
      if (nodes < 2) return false;
      const std::int64_t first = static_cast<std::int64_t>(g() % static_cast<std::uint32_t>(nodes));
      for (std::int64_t i = first; i + 1 < nodes; ++i) doc["nodes"][i]["children"] = Json::array({i + 1});
      if (g() % 2) doc["nodes"][nodes - 1]["children"] = Json::array({first});
      return true;
    }
    case 6: {  // nest an extras deeply (arrays or objects)
      std::vector<Json*> all;
      collect(doc, all);
      Json* target = all[g() % all.size()];
      if (!target->is_object()) return false;
      const int depth = std::array<int, 5>{3, 200, 256, 300, 20000}[g() % 5];
      // A marker string, replaced by the nested JSON when written (dump).
      (*target)["extras"] = std::string("\x01NEST") + (g() % 2 ? "O" : "A") + std::to_string(depth);
      return true;
    }
    case 7: {  // an edge value for a count, offset, length or enum
      std::vector<Json*> all;
      collect(doc, all);
      static constexpr const char* kNumbers[] = {"count", "byteOffset", "byteLength", "byteStride",
                                                 "componentType", "mode"};
      std::vector<Json*> fields;
      for (Json* j : all) {
        if (!j->is_object()) continue;
        for (const char* f : kNumbers) {
          if (j->contains(f)) fields.push_back(&(*j)[f]);
        }
      }
      if (fields.empty()) return false;
      static constexpr std::int64_t kEdges[] = {0, 1, 3, 4, 5, 6, 7, 5120, 5126, 65535, 2147483647, 4294967295,
                                                4294967296, -1};
      *fields[g() % fields.size()] = kEdges[g() % std::size(kEdges)];
      return true;
    }
    case 8: {  // the accessor type, or the asset version
      if (g() % 2) {
        doc["asset"]["version"] = std::array<const char*, 4>{"1.0", "3.0", "2.1", "2"}[g() % 4];
        return true;
      }
      if (array_size(doc, "accessors") == 0) return false;
      Json& a = doc["accessors"][g() % doc["accessors"].size()];
      a["type"] = std::array<const char*, 5>{"SCALAR", "VEC3", "VEC4", "MAT4", "BOGUS"}[g() % 5];
      return true;
    }
    default: {  // a required extension, known or not
      doc["extensionsRequired"].push_back(g() % 2 ? "KHR_materials_unlit" : "EXT_unknown_to_sinew");
      return true;
    }
  }
}

// The document written back, each nesting marker ("\x01NEST", O or A, a
// depth) replaced by that many nested objects or arrays.
inline std::string dump(const Json& doc) {
  std::string text = doc.dump();
  const std::string marker = "\"\\u0001NEST";
  for (std::size_t at = text.find(marker); at != std::string::npos; at = text.find(marker, at)) {
    const std::size_t end = text.find('"', at + marker.size());
    if (end == std::string::npos || end == at + marker.size()) break;
    const bool objects = text[at + marker.size()] == 'O';
    const int depth = std::atoi(text.c_str() + at + marker.size() + 1);
    std::string raw;
    for (int i = 0; i < depth; ++i) raw += objects ? "{\"a\":" : "[";
    raw += "0";
    for (int i = 0; i < depth; ++i) raw += objects ? "}" : "]";
    text.replace(at, end + 1 - at, raw);
    at += raw.size();
  }
  return text;
}

inline std::uint32_t read_u32(const std::uint8_t* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
inline void append_u32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

}  // namespace gltf_mutation

// A structurally mutated copy of the glTF in `bytes` (text or GLB), at most
// `max_size` bytes; empty when `bytes` is not a parseable glTF document or
// the result would not fit (the caller then mutates bytes instead).
inline std::string mutate_gltf(const std::uint8_t* bytes, std::size_t size, std::size_t max_size,
                               unsigned int seed) {
  using namespace gltf_mutation;
  std::mt19937 g(seed);
  std::string_view json_text(reinterpret_cast<const char*>(bytes), size);
  std::string_view rest;  // a GLB's chunks after the JSON chunk
  const bool glb = size >= 20 && std::memcmp(bytes, "glTF", 4) == 0;
  if (glb) {
    const std::uint32_t json_length = read_u32(bytes + 12);
    if (std::memcmp(bytes + 16, "JSON", 4) != 0 || json_length > size - 20) return {};
    json_text = json_text.substr(20, json_length);
    rest = std::string_view(reinterpret_cast<const char*>(bytes), size).substr(20 + json_length);
  }
  // The mutator's own parser is recursive too: leave deep documents to the
  // byte mutations (the importer's nesting limit is what they test).
  int depth = 0, deepest = 0;
  for (const char c : json_text) {
    depth += (c == '[' || c == '{') ? 1 : (c == ']' || c == '}') ? -1 : 0;
    deepest = std::max(deepest, depth);
  }
  if (deepest > 256) return {};
  Json doc = Json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return {};
  bool changed = false;
  for (unsigned tries = 0, wanted = 1 + g() % 3; tries < 8 && wanted > 0; ++tries) {
    if (mutate(doc, g)) {
      changed = true;
      --wanted;
    }
  }
  if (!changed) return {};
  std::string text = dump(doc);
  if (!glb) return text.size() <= max_size ? text : std::string();
  while (text.size() % 4 != 0) text.push_back(' ');
  std::string out;
  out.append("glTF");
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(12 + 8 + text.size() + rest.size()));
  append_u32(out, static_cast<std::uint32_t>(text.size()));
  out.append("JSON");
  out.append(text);
  out.append(rest);
  return out.size() <= max_size ? out : std::string();
}

}  // namespace sinew::fuzz
