#include "runtime/math/affine.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace sinew {

Affine3 Affine3::from_mat4(const Mat4& m) {
  // GLM is column-major: m[col][row].
  Affine3 a;
  for (int r = 0; r < 3; ++r) {
    a.rows[static_cast<std::size_t>(r)] = Vec4(m[0][r], m[1][r], m[2][r], m[3][r]);
  }
  return a;
}

Affine3 Affine3::translation(const Vec3& t) {
  Affine3 a;
  a.rows[0].w = t.x;
  a.rows[1].w = t.y;
  a.rows[2].w = t.z;
  return a;
}

Affine3 Affine3::from_trs(const Vec3& t, const Quat& r, const Vec3& s) {
  const Mat3 rot = glm::mat3_cast(r);
  Affine3 a;
  for (int row = 0; row < 3; ++row) {
    a.rows[static_cast<std::size_t>(row)] =
        Vec4(rot[0][row] * s.x, rot[1][row] * s.y, rot[2][row] * s.z, t[row]);
  }
  return a;
}

Mat4 Affine3::to_mat4() const {
  Mat4 m(1.0f);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m[c][r] = rows[static_cast<std::size_t>(r)][c];
  }
  return m;
}

float Affine3::determinant() const {
  const Vec4& a = rows[0];
  const Vec4& b = rows[1];
  const Vec4& c = rows[2];
  return a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) +
         a.z * (b.x * c.y - b.y * c.x);
}

Affine3 operator*(const Affine3& a, const Affine3& b) {
  Affine3 out;
  for (std::size_t r = 0; r < 3; ++r) {
    const Vec4& ar = a.rows[r];
    out.rows[r] = ar.x * b.rows[0] + ar.y * b.rows[1] + ar.z * b.rows[2] + Vec4(0, 0, 0, ar.w);
  }
  return out;
}

Affine3 inverse(const Affine3& m) {
  // Inverse of the 3x3 part by the adjugate, then t' = -R^-1 t.
  const Vec4& a = m.rows[0];
  const Vec4& b = m.rows[1];
  const Vec4& c = m.rows[2];
  const float inv_det = 1.0f / m.determinant();
  Affine3 out;
  out.rows[0] = Vec4((b.y * c.z - b.z * c.y), (a.z * c.y - a.y * c.z), (a.y * b.z - a.z * b.y), 0) *
                inv_det;
  out.rows[1] = Vec4((b.z * c.x - b.x * c.z), (a.x * c.z - a.z * c.x), (a.z * b.x - a.x * b.z), 0) *
                inv_det;
  out.rows[2] = Vec4((b.x * c.y - b.y * c.x), (a.y * c.x - a.x * c.y), (a.x * b.y - a.y * b.x), 0) *
                inv_det;
  const Vec3 t = m.translation_part();
  const Vec3 ti = -out.transform_vector(t);
  out.rows[0].w = ti.x;
  out.rows[1].w = ti.y;
  out.rows[2].w = ti.z;
  return out;
}

bool is_finite(const Affine3& m) {
  for (const Vec4& r : m.rows) {
    if (!std::isfinite(r.x) || !std::isfinite(r.y) || !std::isfinite(r.z) || !std::isfinite(r.w)) {
      return false;
    }
  }
  return true;
}

}  // namespace sinew
