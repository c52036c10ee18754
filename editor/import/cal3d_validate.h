// Pre-validation of each file before Cal3D reads it: binary .csf/.cmf/.caf
// walked structure by structure, XML materials (.xrf) held to the one form
// Cal3D writes. Separate because Cal3D 0.11 trusts its input: these checks
// stand between untrusted bytes and its loaders, and use nothing of Cal3D.
#pragma once

#include <string>

#include "runtime/core/expected.h"

namespace sinew::editor::cal3d_detail {

// OK for a file Cal3D may read: a binary skeleton, mesh or animation (by its
// magic) that walks whole, an .xrf of the checked form, or any other file
// (left to Cal3D's own checks). Errors name `path` and the field.
Status validate_binary(const std::string& path);

}  // namespace sinew::editor::cal3d_detail
