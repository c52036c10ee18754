// Math vocabulary types on GLM. Sinew works in single precision: positions in
// the file's own units (docs/ANIMATION.md, "Importers"), right-handed, column vectors.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace sinew {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using Quat = glm::quat;

}  // namespace sinew
