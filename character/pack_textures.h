// The TEXR section of a character pack (docs/PACK_FORMAT.md, "Textures"):
// which material has which colour map, and each map's whole mip chain as
// the renderer samples it (runtime/image/texture.h). Optional: a pack
// whose materials have no texture has no TEXR and loads as before.
#pragma once

#include <cstddef>
#include <vector>

#include "runtime/core/status.h"
#include "runtime/mesh/skinned_mesh.h"
#include "runtime/pack/section_codec.h"

namespace sinew::character {

inline constexpr SectionId kTexturesSection = make_section_id("TEXR");
inline constexpr std::uint32_t kTexturesVersion = 1;

// True when some material of `mesh` has a texture (the section is written).
bool has_textures(const SkinnedMesh& mesh);

std::vector<std::byte> encode_textures(const SkinnedMesh& mesh);

// Into `mesh` (whose MESH section was decoded): every count is checked
// against the bytes left before anything is allocated, and the result
// against the mesh (check_material_textures). Errors name the pack and
// the field: "x.pack: TEXR.textures[1].levels[2].width = 7: ...".
Status decode_textures(SectionDecoder& d, SkinnedMesh& mesh);

}  // namespace sinew::character
