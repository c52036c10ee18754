// glTF base colour textures: each material's
// pbrMetallicRoughness.baseColorTexture (its image, its sampler's wrap
// modes; the mesh reads the texCoord set it names, gltf_mesh.h) decoded
// into the mesh's textures (runtime/image/texture_decode.h). An image that
// is missing, refused by the asset sandbox or cannot be decoded is one
// warning naming the material and the image; the material keeps its
// colour and the import goes on.
#pragma once

#include <string>
#include <vector>

#include "editor/import/gltf_context.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::editor::gltf_detail {

// The encoded bytes tinygltf handed over for each image (empty: none).
using ImageBytes = std::vector<std::vector<unsigned char>>;

// Fills mesh.material_texture (one per material, the default material
// included) and mesh.textures; `material_names` names them in warnings.
void import_textures(const Ctx& c, const ImageBytes& images, const std::vector<std::string>& material_names,
                     SkinnedMesh& mesh, std::vector<std::string>& warnings);

}  // namespace sinew::editor::gltf_detail
