// Structural checks of Cal3D's XML skeletons (.xsf), animations (.xaf) and
// meshes (.xmf) before Cal3D reads them, the XML counterpart of the binary
// walks in cal3d_validate.cpp.
//
// Cal3D 0.11's XML loaders trust the file as its binary ones do: they read
// numbers with atoi/atof and streams (so `abc` becomes 0 and `nan` passes),
// construct strings from attributes they have not checked are present, and
// recurse once per nesting level in their XML parser. And the bone links
// they build are used unchecked, as in the binary skeleton. So each file
// must have the shape Cal3D itself writes, with every number parsed here:
// counts that match the elements present, ids in range, finite values.
#pragma once

#include <string>
#include <string_view>

#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

enum class Cal3dXmlKind { kSkeleton, kAnimation, kMesh };

// OK when `text` (the whole of `file`) is a well-formed file of `kind`;
// otherwise an error naming `file`, the element path and the value.
Status check_cal3d_xml(std::string_view text, const std::string& file, Cal3dXmlKind kind);

}  // namespace sinew::editor::cal3d_detail
