// One entry point for every model format the tools accept, chosen by the
// file's extension: glTF 2.0 (.gltf, .glb), Cal3D (.cfg) and content packs
// (.pack: the model stored in the pack; its fuzzy data is not needed here).
#pragma once

#include <string>

#include "character/model.h"
#include "editor/import/gltf_importer.h"
#include "runtime/core/expected.h"

namespace sinew::editor {

// Errors: kNotFound (no such file), kInvalidArgument (unknown extension, or
// Cal3D in a build without libcal3d), and the importer's or loader's own.
// `gltf`: the glTF importer's options (the folders external files may come from).
Expected<character::Model> load_model(const std::string& path, const GltfImportOptions& gltf = {});

// The lower-case extension with its dot (".glb"), "" when there is none.
std::string lower_extension(const std::string& path);

}  // namespace sinew::editor
