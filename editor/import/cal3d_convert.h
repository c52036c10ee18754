// Conversion of what Cal3D loaded into Sinew's types: the skeleton, each
// mesh's submeshes appended to the SkinnedMesh, each animation as a clip,
// with Cal3D's conventions mapped (cal3d_importer.h). Separate because it is
// the part that knows both Cal3D's core objects and Sinew's types.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <cal3d/cal3d.h>

#include "character/model.h"
#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

Expected<anim::Skeleton> convert_skeleton(CalCoreSkeleton& core, const std::string& file,
                                          std::vector<int>& raw_to_sorted);

struct MeshContext {
  SkinnedMesh* mesh = nullptr;
  const std::vector<int>* raw_to_sorted = nullptr;
  std::size_t material_count = 0;   // materials loaded from the .cfg
  bool uses_default_material = false;
};

Status convert_mesh(CalCoreMesh& core, const std::string& file, MeshContext& ctx);

Expected<anim::Clip> convert_clip(CalCoreAnimation& core, const std::string& name,
                                  const std::string& file, const anim::Skeleton& skeleton,
                                  const std::vector<int>& remap);

}  // namespace sinew::editor::cal3d_detail
