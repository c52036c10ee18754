// Colour maps named by file, as Cal3D materials name them (the first
// <MAP> of a .xrf is its diffuse texture): each read and decoded once
// (runtime/image/texture_decode.h) into the mesh's textures. A name that
// leaves the model's folder, or a file that is missing or cannot be
// decoded, is one warning naming the material and the file; the material
// keeps its colour and the import goes on.
#pragma once

#include <string>
#include <vector>

#include "runtime/mesh/skinned_mesh.h"

namespace sinew::editor {

// `maps[m]` is material m's map as written in its file ("" for none),
// relative to `folder` (the material file's folder). Fills
// mesh.material_texture (left empty when no map was loaded) and
// mesh.textures. Cal3D maps repeat (it leaves wrapping to the viewer).
void load_material_maps(const std::vector<std::string>& maps, const std::vector<std::string>& material_names,
                        const std::string& folder, SkinnedMesh& mesh, std::vector<std::string>& warnings);

}  // namespace sinew::editor
