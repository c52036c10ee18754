#include "editor/import/material_maps.h"

#include <filesystem>
#include <map>

#include "runtime/image/texture_decode.h"

namespace sinew::editor {

void load_material_maps(const std::vector<std::string>& maps, const std::vector<std::string>& material_names,
                        const std::string& folder, SkinnedMesh& mesh, std::vector<std::string>& warnings) {
  namespace fs = std::filesystem;
  mesh.material_texture.assign(mesh.material_colors.size(), kNoTexture);
  std::map<std::string, std::uint32_t> made;  // one decode per file
  bool any = false;
  for (std::size_t m = 0; m < maps.size() && m < mesh.material_colors.size(); ++m) {
    if (maps[m].empty()) continue;
    const fs::path relative(maps[m]);
    const std::string path = (fs::path(folder) / relative).lexically_normal().string();
    const auto skip = [&](const std::string& why) {
      warnings.push_back("material '" + material_names[m] + "': map " + maps[m] + " not used (" + why +
                         "): the material's colour is used");
    };
    if (mesh.uvs.empty()) {
      skip("the mesh has no texture coordinates");
      continue;
    }
    bool leaves = relative.is_absolute();
    for (const fs::path& part : relative) leaves |= part == "..";
    if (leaves) {
      skip("outside the model's folder");
      continue;
    }
    if (auto found = made.find(path); found != made.end()) {
      mesh.material_texture[m] = found->second;
      any = true;
      continue;
    }
    Expected<Texture> texture = read_texture(path, TextureWrap::kRepeat, TextureWrap::kRepeat);
    if (!texture.ok()) {
      skip(texture.status().message());
      continue;
    }
    texture->name = relative.string();
    const auto index = static_cast<std::uint32_t>(mesh.textures.size());
    mesh.textures.push_back(std::move(*texture));
    made.emplace(path, index);
    mesh.material_texture[m] = index;
    any = true;
  }
  if (!any) mesh.material_texture.clear();
}

}  // namespace sinew::editor
