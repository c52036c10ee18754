// TRS decomposition (gltf_transforms.h): matrices split into TRS within a
// tolerance, and nodes' local transforms read and checked.
#include "editor/import/gltf_transforms.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace sinew::editor::gltf_detail {

double max_abs_diff(const DMat4& a, const DMat4& b) {
  double d = 0.0;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 3; ++row) d = std::max(d, std::abs(a[col][row] - b[col][row]));
  }
  return d;
}

bool decompose(const DMat4& m, Trs& out) {
  if (std::abs(m[0][3]) > 1e-6 || std::abs(m[1][3]) > 1e-6 || std::abs(m[2][3]) > 1e-6 ||
      std::abs(m[3][3] - 1.0) > 1e-6) {
    return false;
  }
  const DVec3 c0(m[0]), c1(m[1]), c2(m[2]);
  DVec3 s(glm::length(c0), glm::length(c1), glm::length(c2));
  const double smax = std::max({s.x, s.y, s.z});
  if (!(std::min({s.x, s.y, s.z}) > 1e-12 * std::max(1.0, smax))) return false;
  if (glm::determinant(glm::dmat3(m)) < 0.0) s = -s;
  const glm::dmat3 rot(c0 / s.x, c1 / s.y, c2 / s.z);
  out.t = DVec3(m[3]);
  out.r = glm::normalize(glm::quat_cast(rot));
  out.s = s;
  return max_abs_diff(out.matrix(), m) <= 1e-5 * std::max(1.0, smax);
}

bool is_similarity(const Trs& p) {
  const double m = std::max({std::abs(p.s.x), std::abs(p.s.y), std::abs(p.s.z)});
  return std::abs(p.s.x - p.s.y) <= 1e-6 * m && std::abs(p.s.x - p.s.z) <= 1e-6 * m;
}

bool is_identity(const DMat4& m) { return max_abs_diff(m, DMat4(1.0)) <= 1e-12; }

Status node_local(const Ctx& c, std::size_t i, DMat4& matrix, Trs& trs, bool& trs_ok) {
  const tinygltf::Node& n = c.model.nodes[i];
  const std::string field = idx("nodes", i);
  trs_ok = true;
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) {
      return c.error(ErrorCode::kInvalidData, field + ".matrix", std::to_string(n.matrix.size()),
                     "a matrix has 16 numbers");
    }
    for (int k = 0; k < 16; ++k) {
      const double v = n.matrix[static_cast<std::size_t>(k)];
      if (!std::isfinite(v)) {
        return c.error(ErrorCode::kInvalidData, idx(field + ".matrix", static_cast<std::size_t>(k)),
                       num(v), "not a finite number");
      }
      matrix[k / 4][k % 4] = v;  // column-major, like glm
    }
    trs_ok = decompose(matrix, trs);
    return {};
  }
  auto check = [&](const std::vector<double>& v, std::size_t want, const char* name) -> Status {
    if (v.empty()) return {};
    if (v.size() != want) {
      return c.error(ErrorCode::kInvalidData, field + "." + name, std::to_string(v.size()),
                     "expected " + std::to_string(want) + " numbers");
    }
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (!std::isfinite(v[k])) {
        return c.error(ErrorCode::kInvalidData, idx(field + "." + name, k), num(v[k]),
                       "not a finite number");
      }
    }
    return {};
  };
  SINEW_RETURN_IF_ERROR(check(n.translation, 3, "translation"));
  SINEW_RETURN_IF_ERROR(check(n.rotation, 4, "rotation"));
  SINEW_RETURN_IF_ERROR(check(n.scale, 3, "scale"));
  if (!n.translation.empty()) trs.t = DVec3(n.translation[0], n.translation[1], n.translation[2]);
  if (!n.rotation.empty()) {
    const DQuat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    const double len = glm::length(q);
    if (!(len > 1e-12)) {
      return c.error(ErrorCode::kInvalidData, field + ".rotation", "0",
                     "rotation quaternion has zero length");
    }
    trs.r = q / len;
  }
  if (!n.scale.empty()) trs.s = DVec3(n.scale[0], n.scale[1], n.scale[2]);
  matrix = trs.matrix();
  return {};
}

Affine3 to_affine(const DMat4& m) { return Affine3::from_mat4(Mat4(m)); }

}  // namespace sinew::editor::gltf_detail
