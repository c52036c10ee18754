// The glTF import in order (gltf_importer.h says what becomes of a file):
// the file is read within the limits and parsed by tinygltf; convert() then
// runs the parts: node graph, skeleton plan and skeleton (gltf_skeleton.h),
// materials (here), meshes (gltf_mesh.h) and clips (gltf_clips.h).
#include "editor/import/gltf_clips.h"
#include "editor/import/gltf_container.h"
#include "editor/import/gltf_importer.h"
#include "editor/import/gltf_mesh.h"
#include "editor/import/gltf_skeleton.h"
#include "editor/import/gltf_textures.h"
#include "runtime/io/atomic_file.h"
#include "runtime/io/regular_file.h"

#include <tiny_gltf.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <new>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

namespace sinew::editor {
namespace {

constexpr const char* kDefaultMaterialName = "<default>";

using gltf_detail::add_primitive;
using gltf_detail::build_clips;
using gltf_detail::build_graph;
using gltf_detail::build_skeleton;
using gltf_detail::Ctx;
using gltf_detail::idx;
using gltf_detail::MeshBuilder;
using gltf_detail::NodeGraph;
using gltf_detail::plan_skeleton;
using gltf_detail::SkeletonPlan;

Expected<character::Model> convert(const Ctx& c, const gltf_detail::ImageBytes& images) {
  character::Model out;
  out.source = c.file;
  SINEW_ASSIGN_OR_RETURN(NodeGraph g, build_graph(c));
  SINEW_ASSIGN_OR_RETURN(SkeletonPlan plan, plan_skeleton(c, g));
  if (plan.joint_nodes.empty()) {
    return c.error(ErrorCode::kNotFound, "nodes", "", "no node instantiates a mesh");
  }

  std::vector<bool> animated(c.model.nodes.size(), false);
  for (const tinygltf::Animation& a : c.model.animations) {
    for (const tinygltf::AnimationChannel& ch : a.channels) {
      if (ch.target_node >= 0 && static_cast<std::size_t>(ch.target_node) < animated.size() &&
          ch.target_path != "weights") {
        animated[static_cast<std::size_t>(ch.target_node)] = true;
      }
    }
  }
  std::vector<int> raw_to_sorted;
  SINEW_ASSIGN_OR_RETURN(out.skeleton, build_skeleton(c, g, plan, animated, raw_to_sorted));

  MeshBuilder b;
  // Materials: the file's, then a default one if some primitive has none.
  const std::size_t nmat = c.model.materials.size();
  for (std::size_t i = 0; i < nmat; ++i) {
    const tinygltf::Material& mat = c.model.materials[i];
    const std::vector<double>& f = mat.pbrMetallicRoughness.baseColorFactor;
    Vec3 color(1.0f);
    if (f.size() >= 3) {
      color = Vec3(static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2]));
      if (!std::isfinite(color.x) || !std::isfinite(color.y) || !std::isfinite(color.z)) {
        return c.error(ErrorCode::kInvalidData,
                       idx("materials", i) + ".pbrMetallicRoughness.baseColorFactor", "",
                       "not a finite colour");
      }
    }
    b.mesh.material_colors.push_back(color);
    out.material_names.push_back(mat.name.empty() ? "material_" + std::to_string(i) : mat.name);
  }
  bool default_used = false;
  for (std::size_t m = 0; m < c.model.meshes.size(); ++m) {
    for (std::size_t n = 0; n < c.model.nodes.size(); ++n) {
      if (c.model.nodes[n].mesh != static_cast<int>(m)) continue;
      const auto& prims = c.model.meshes[m].primitives;
      for (std::size_t p = 0; p < prims.size(); ++p) {
        const int mat = prims[p].material;
        if (mat < -1 || mat >= static_cast<int>(nmat)) {
          return c.error(ErrorCode::kOutOfBounds,
                         idx(idx("meshes", m) + ".primitives", p) + ".material",
                         std::to_string(mat), "no such material");
        }
        if (mat == -1) default_used = true;
        const std::uint32_t material =
            mat == -1 ? static_cast<std::uint32_t>(nmat) : static_cast<std::uint32_t>(mat);
        SINEW_RETURN_IF_ERROR(add_primitive(c, g, plan, raw_to_sorted, n, m, p, material, b));
        // Checked per primitive: a mesh instanced by many nodes is copied
        // per node, so memory stays within the limit plus one primitive.
        if (b.mesh.triangles.size() > c.limits.max_triangles) {
          return c.limit(idx("nodes", n) + ".mesh", b.mesh.triangles.size(), "triangles", c.limits.max_triangles,
                         "--max-triangles");
        }
      }
    }
  }
  out.mesh = std::move(b.mesh);
  if (default_used) {
    out.mesh.material_colors.push_back(Vec3(1.0f));
    out.material_names.push_back(kDefaultMaterialName);
  }
  if (out.mesh.triangles.empty()) {
    return c.error(ErrorCode::kNotFound, "meshes", "", "the file has no triangles");
  }
  gltf_detail::import_textures(c, images, out.material_names, out.mesh, out.warnings);

  SINEW_ASSIGN_OR_RETURN(out.clips, build_clips(c, plan, out.skeleton, raw_to_sorted));
  // What bakes, but not as the file means it: one clear line each.
  if (c.model.skins.empty()) {
    out.warnings.push_back(c.file + ": skins: none: a static model; it bakes as rigid parts (" +
                           std::to_string(out.skeleton.joint_count()) +
                           (out.skeleton.joint_count() == 1 ? " bone" : " bones") +
                           "), where a host's static mesh (World::add_static_mesh) needs no bake");
  }
  std::size_t morph_targets = 0;
  std::string first_morph;
  for (std::size_t m = 0; m < c.model.meshes.size(); ++m) {
    const auto& prims = c.model.meshes[m].primitives;
    for (std::size_t p = 0; p < prims.size(); ++p) {
      if (prims[p].targets.empty()) continue;
      if (first_morph.empty()) first_morph = idx(idx("meshes", m) + ".primitives", p) + ".targets";
      morph_targets += prims[p].targets.size();
    }
  }
  if (morph_targets > 0) {
    out.warnings.push_back(c.file + ": " + first_morph + ": " + std::to_string(morph_targets) +
                           " morph targets (all meshes), ignored with their weights' animation: Sinew deforms "
                           "by bones only, so the meshes bake and render in their base shape");
  }
  // Weights that do not sum to 1 are renormalised here, with a warning when
  // they were off by more than rounding (the rule all importers share).
  SINEW_RETURN_IF_ERROR(character::normalize_skin_weights(out));
  return out;
}

// tinygltf hands each image's encoded bytes here (from a buffer view, a
// data URI or a file read through guarded_read); they are kept, not
// decoded: only the base colour textures are decoded later
// (gltf_textures.h), so a broken image that no material uses costs nothing
// and one that a material uses is a warning, not a failed import.
bool keep_image_bytes(tinygltf::Image*, const int image_idx, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* user) {
  auto& images = *static_cast<gltf_detail::ImageBytes*>(user);
  if (image_idx < 0 || bytes == nullptr || size <= 0) return true;
  const auto i = static_cast<std::size_t>(image_idx);
  if (images.size() <= i) images.resize(i + 1);
  images[i].assign(bytes, bytes + size);
  return true;
}

// tinygltf's file reads, kept inside the asset roots (it also looks in the
// current directory), to regular files, and to the import's byte limit
// (the document's own bytes count first).
struct GuardedFs {
  const AssetRoots* roots = nullptr;
  std::size_t bytes_left = 0;
  std::size_t max_bytes = 0;
  std::string refused, why;  // the first path refused, and why
  bool over_limit = false;
};

bool guarded_read(std::vector<unsigned char>* out, std::string* err, const std::string& filepath, void* user) {
  auto& fs = *static_cast<GuardedFs*>(user);
  std::string why;
  if (fs.roots->root_of(filepath).empty()) {
    why = "outside the asset's folder " + fs.roots->asset_folder().string();
  } else if (Status s = check_regular_file(filepath); !s.ok()) {
    why = s.message();
  } else {
    // The size first, so that a huge file is not read at all; then what
    // was read (the file may have grown in between).
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(filepath, ec);
    const bool fits = !ec && size <= fs.bytes_left;
    if (fits && !tinygltf::ReadWholeFile(out, err, filepath, nullptr)) return false;
    if (fits && out->size() <= fs.bytes_left) {
      fs.bytes_left -= out->size();
      return true;
    }
    if (ec) {
      why = "cannot read its size: " + ec.message();
    } else {
      fs.over_limit = true;
      why = std::to_string(fits ? out->size() : size) + " bytes, past the import limit of " +
            std::to_string(fs.max_bytes) + " bytes for the file and its buffers (raise it with --max-bytes)";
      out->clear();
    }
  }
  if (fs.refused.empty()) {
    fs.refused = filepath;
    fs.why = why;
  }
  if (err) *err += why;
  return false;
}

}  // namespace

Expected<character::Model> import_gltf(const std::string& path, const GltfImportOptions& options) {
  const std::size_t max_bytes = options.limits.max_bytes;
  const auto too_big = [&](std::uintmax_t size) {
    return make_error(ErrorCode::kLimitExceeded, path, "size", std::to_string(size) + " bytes",
                      "more bytes than the import limit of " + std::to_string(max_bytes) +
                          " (raise it with --max-bytes)");
  };
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  std::error_code size_error;
  const std::uintmax_t size = std::filesystem::file_size(path, size_error);
  if (!size_error && size > max_bytes) return too_big(size);
  SINEW_ASSIGN_OR_RETURN(const std::string bytes, read_file_text(path));
  if (bytes.size() > max_bytes) return too_big(bytes.size());
  // tinygltf takes 32-bit lengths.
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return make_error(ErrorCode::kLimitExceeded, path, "", std::to_string(bytes.size()) + " bytes",
                      "glTF files of 4 GiB or more are not supported");
  }
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  // Bounded nesting before tinygltf's recursive parser sees the JSON.
  std::string_view json = bytes;
  std::optional<GlbChunks> glb;
  if (binary) {
    Expected<GlbChunks> chunks = check_glb(bytes, path);
    if (!chunks.ok()) return chunks.status();
    glb = *chunks;
    json = glb->json;
  } else {
    SINEW_RETURN_IF_ERROR(check_json_nesting(bytes, kMaxJsonNesting, path, "json"));
  }
  // External files only from the asset's folder (and the allowed roots).
  const AssetRoots roots(path, options.asset_roots);
  SINEW_RETURN_IF_ERROR(check_gltf_document(json, path, roots, glb ? &*glb : nullptr));
  const std::string base_dir = std::filesystem::path(path).parent_path().string();

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  gltf_detail::ImageBytes images;
  loader.SetImageLoader(keep_image_bytes, &images);
  GuardedFs guarded{&roots, max_bytes - bytes.size(), max_bytes, {}, {}, false};
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&tinygltf::FileExists, &tinygltf::ExpandFilePath, &guarded_read,
                                              &tinygltf::WriteWholeFile, &guarded});
  std::string err, warn;
  bool loaded = false;
  try {
    const auto length = static_cast<unsigned int>(bytes.size());
    loaded = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                  reinterpret_cast<const unsigned char*>(bytes.data()), length,
                                                  base_dir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), length, base_dir);
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::kLimitExceeded, path, binary ? "glb" : "json", std::to_string(bytes.size()) + " bytes",
                      "out of memory while tinygltf parsed the file");
  } catch (const std::exception& e) {
    // tinygltf or its JSON parser may throw on hostile input; we must not.
    err = e.what();
    loaded = false;
  } catch (...) {
    err = "unknown exception";
    loaded = false;
  }
  if (!loaded && !guarded.refused.empty()) {
    return make_error(guarded.over_limit ? ErrorCode::kLimitExceeded : ErrorCode::kInvalidData, path, "uri",
                      guarded.refused, "not read: " + guarded.why);
  }
  if (!loaded) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    // tinygltf ends each of its messages with a newline: one line here.
    for (std::size_t at = err.find('\n'); at != std::string::npos; at = err.find('\n', at)) err.replace(at, 1, "; ");
    return make_error(ErrorCode::kInvalidData, path, binary ? "glb" : "json", "",
                      "tinygltf could not parse the file: " + (err.empty() ? warn : err));
  }
  // asset.version is "major.minor"; only major version 2 is this format.
  const std::string& version = model.asset.version;
  if (version.rfind("2.", 0) != 0) {
    return make_error(ErrorCode::kUnsupportedVersion, path, "asset.version", version.empty() ? "(none)" : version,
                      version.rfind("1.", 0) == 0 ? "glTF 1.0 is not supported (glTF 2.0 only)"
                                                  : "only glTF 2.x is supported");
  }
  const Ctx c{model, path, options.limits};
  return convert(c, images);
}

}  // namespace sinew::editor
