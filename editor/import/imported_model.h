// ImportedModel: what every importer produces (DESIGN.md section 9), in
// Sinew's own types. Importers are the only code that knows file formats
// other than the content pack.
//
// Triangle order is part of the contract (the ray tracer reports triangle
// ids in it): Cal3D — meshes in .cfg order, then submeshes and faces in file
// order; glTF — meshes in array order, primitives in order, triangles in
// index order. Positions stay in the file's units after the file's own scale;
// nothing is re-oriented (glTF is Y-up, Cal3D models usually Z-up).
#pragma once

#include <string>
#include <vector>

#include "animation/clip.h"
#include "animation/skeleton.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::editor {

struct ImportedModel {
  std::string source;  // the file it came from
  anim::Skeleton skeleton;
  SkinnedMesh mesh;  // joint indices refer to skeleton's (sorted) joint order
  std::vector<anim::Clip> clips;
  std::vector<std::string> material_names;  // parallel to mesh.material_colors

  // The clip called `name`, or "#<index>" for the index-th clip.
  const anim::Clip* find_clip(const std::string& name) const;
};

}  // namespace sinew::editor
