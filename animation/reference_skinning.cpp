#include "animation/reference_skinning.h"

#include <cmath>
#include <string>

namespace sinew::anim {

Status skin_reference(const SkinnedMesh& mesh, std::span<const Affine3> skin,
                      std::span<Vec3> positions, std::span<Vec3> normals) {
  const std::size_t n = mesh.vertex_count();
  if (positions.size() != n) {
    return invalid_argument("positions", std::to_string(positions.size()),
                            "expected " + std::to_string(n) + " entries");
  }
  const bool want_normals = !normals.empty();
  if (want_normals && (normals.size() != n || mesh.normals.size() != n)) {
    return invalid_argument("normals", std::to_string(normals.size()),
                            "expected " + std::to_string(n) + " entries and mesh normals");
  }
  if (mesh.joints.size() != n || mesh.weights.size() != n) {
    return invalid_argument("mesh.joints/weights", std::to_string(mesh.joints.size()),
                            "one influence row per vertex expected");
  }
  for (std::size_t v = 0; v < n; ++v) {
    double m[3][4] = {};
    for (int i = 0; i < kMaxInfluences; ++i) {
      const double w = mesh.weights[v][static_cast<std::size_t>(i)];
      if (w == 0.0) continue;
      const std::size_t j = mesh.joints[v][static_cast<std::size_t>(i)];
      if (j >= skin.size()) {
        return make_error(ErrorCode::kOutOfBounds, "", "joints[" + std::to_string(v) + "]",
                          std::to_string(j), "joint index past the " + std::to_string(skin.size()) +
                                                 " skinning matrices");
      }
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] += w * double(skin[j](r, c));
    }
    const glm::dvec3 p(mesh.positions[v]);
    for (int r = 0; r < 3; ++r) {
      positions[v][r] = static_cast<float>(m[r][0] * p.x + m[r][1] * p.y + m[r][2] * p.z + m[r][3]);
    }
    if (want_normals) {
      const glm::dvec3 q(mesh.normals[v]);
      double out[3];
      for (int r = 0; r < 3; ++r) out[r] = m[r][0] * q.x + m[r][1] * q.y + m[r][2] * q.z;
      const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
      const double inv = len > 0.0 ? 1.0 / len : 0.0;
      normals[v] = Vec3(float(out[0] * inv), float(out[1] * inv), float(out[2] * inv));
    }
  }
  return {};
}

}  // namespace sinew::anim
