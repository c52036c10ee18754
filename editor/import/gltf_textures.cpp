#include "editor/import/gltf_textures.h"

#include <map>
#include <span>
#include <utility>

#include "runtime/image/texture_decode.h"

namespace sinew::editor::gltf_detail {
namespace {

TextureWrap wrap_of(int gl_wrap) {
  switch (gl_wrap) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::kClamp;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::kMirror;
    default: return TextureWrap::kRepeat;  // REPEAT, and the spec's default
  }
}

}  // namespace

void import_textures(const Ctx& c, const ImageBytes& images, const std::vector<std::string>& material_names,
                     SkinnedMesh& mesh, std::vector<std::string>& warnings) {
  mesh.material_texture.assign(mesh.material_colors.size(), kNoTexture);
  // One decode per image and wrap pair, however many materials share it.
  std::map<std::pair<int, std::pair<int, int>>, std::uint32_t> made;
  for (std::size_t m = 0; m < c.model.materials.size() && m < mesh.material_colors.size(); ++m) {
    const tinygltf::TextureInfo& info = c.model.materials[m].pbrMetallicRoughness.baseColorTexture;
    if (info.index < 0) continue;
    const std::string field = idx("materials", m) + ".pbrMetallicRoughness.baseColorTexture";
    const auto skip = [&](const std::string& why) {
      warnings.push_back(c.file + ": " + field + " of material '" + material_names[m] + "' not used (" + why +
                         "): the material's colour is used");
    };
    if (mesh.uvs.empty()) {
      skip("the mesh has no TEXCOORD_" + std::to_string(info.texCoord));
      continue;
    }
    if (static_cast<std::size_t>(info.index) >= c.model.textures.size()) {
      skip("no texture " + std::to_string(info.index));
      continue;
    }
    const tinygltf::Texture& texture = c.model.textures[static_cast<std::size_t>(info.index)];
    if (texture.source < 0 || static_cast<std::size_t>(texture.source) >= c.model.images.size()) {
      skip("textures[" + std::to_string(info.index) + "] has no image");
      continue;
    }
    const auto image = static_cast<std::size_t>(texture.source);
    int wrap_s = TINYGLTF_TEXTURE_WRAP_REPEAT, wrap_t = TINYGLTF_TEXTURE_WRAP_REPEAT;
    if (texture.sampler >= 0 && static_cast<std::size_t>(texture.sampler) < c.model.samplers.size()) {
      wrap_s = c.model.samplers[static_cast<std::size_t>(texture.sampler)].wrapS;
      wrap_t = c.model.samplers[static_cast<std::size_t>(texture.sampler)].wrapT;
    }
    const auto key = std::make_pair(texture.source, std::make_pair(wrap_s, wrap_t));
    if (auto found = made.find(key); found != made.end()) {
      mesh.material_texture[m] = found->second;
      continue;
    }
    const tinygltf::Image& source = c.model.images[image];
    const std::string name = source.uri.empty() || source.uri.rfind("data:", 0) == 0
                                 ? c.file + ": " + idx("images", image)
                                 : source.uri;
    if (image >= images.size() || images[image].empty()) {
      skip(idx("images", image) + (source.uri.empty() ? "" : " '" + source.uri + "'") + " could not be read");
      continue;
    }
    const std::span<const unsigned char> bytes = images[image];
    Expected<Texture> decoded =
        decode_texture(std::as_bytes(bytes), source.mimeType, name, wrap_of(wrap_s), wrap_of(wrap_t));
    if (!decoded.ok()) {
      skip(decoded.status().message());
      continue;
    }
    const auto index = static_cast<std::uint32_t>(mesh.textures.size());
    mesh.textures.push_back(std::move(*decoded));
    made.emplace(key, index);
    mesh.material_texture[m] = index;
  }
  bool any = false;
  for (const std::uint32_t t : mesh.material_texture) any |= t != kNoTexture;
  if (!any) mesh.material_texture.clear();
}

}  // namespace sinew::editor::gltf_detail
