// Pre-validation of each file before Cal3D reads it: binary .csf/.cmf/.caf
// walked structure by structure, XML files held to the one form Cal3D
// writes (.xrf here, the others in cal3d_xml_check.h). Separate because Cal3D 0.11 trusts its input: these checks
// stand between untrusted bytes and its loaders, and use nothing of Cal3D.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

// OK for a file Cal3D may read: a binary skeleton, mesh or animation (by its
// magic) that walks whole, an XML file (.xsf, .xaf, .xmf, .xrf) of the
// checked form, or any other file (left to Cal3D's own checks). Errors name
// `path` and the field.
Status validate_binary(const std::string& path);

// The links of a skeleton of parents.size() bones, binary or XML: parent and
// child ids in range, each child naming its lister as parent, no cycles.
Status check_bone_links(const std::vector<std::int32_t>& parents,
                        const std::vector<std::vector<std::int32_t>>& children, const std::string& file);

}  // namespace sinew::editor::cal3d_detail
