#include "editor/import/model_loader.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "character/pack.h"
#include "editor/import/gltf_importer.h"
#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#include "runtime/io/regular_file.h"
#endif

namespace sinew::editor {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Expected<character::Model> load_model(const std::string& path, const GltfImportOptions& gltf) {
  const std::string ext = lower_extension(path);
  const bool is_gltf = ext == ".gltf" || ext == ".glb";
  if (!is_gltf && ext != ".cfg" && ext != ".pack") {
    return make_error(ErrorCode::kInvalidArgument, path, "extension", ext.empty() ? "(none)" : ext,
                      "unsupported model format (expected .gltf, .glb, .cfg or .pack)");
  }
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  if (is_gltf) return import_gltf(path, gltf);
  if (ext == ".pack") {
    SINEW_ASSIGN_OR_RETURN(character::Pack pack, character::Pack::open(path));
    return pack.model();
  }
#if SINEW_HAVE_CAL3D
  return import_cal3d(path);
#else
  return make_error(ErrorCode::kInvalidArgument, path, "", "", "this build has no Cal3D importer (libcal3d missing)");
#endif
}

}  // namespace sinew::editor
