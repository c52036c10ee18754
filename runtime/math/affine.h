// Affine3: a 3x4 affine transform stored as three rows [R | t].
//
// This is the unit of exchange between animation/ and raytrace/: one frame
// of a character is a contiguous span of Affine3 (one per bone). Row-major
// rows of 4 floats let SIMD skinning load a row per register, and 48 bytes
// per bone keep a 60-bone skeleton in 45 cache lines.
#pragma once

#include <array>

#include "runtime/math/types.h"

namespace sinew {

struct Affine3 {
  // rows[i] = (m_i0, m_i1, m_i2, t_i): p' = R p + t.
  std::array<Vec4, 3> rows{Vec4(1, 0, 0, 0), Vec4(0, 1, 0, 0), Vec4(0, 0, 1, 0)};

  static Affine3 identity() { return {}; }
  static Affine3 from_mat4(const Mat4& m);  // drops the projective row
  static Affine3 translation(const Vec3& t);
  static Affine3 from_trs(const Vec3& t, const Quat& r, const Vec3& s);

  Mat4 to_mat4() const;

  float operator()(int row, int col) const { return rows[static_cast<std::size_t>(row)][col]; }
  Vec3 translation_part() const { return {rows[0].w, rows[1].w, rows[2].w}; }

  Vec3 transform_point(const Vec3& p) const {
    return {rows[0].x * p.x + rows[0].y * p.y + rows[0].z * p.z + rows[0].w,
            rows[1].x * p.x + rows[1].y * p.y + rows[1].z * p.z + rows[1].w,
            rows[2].x * p.x + rows[2].y * p.y + rows[2].z * p.z + rows[2].w};
  }
  Vec3 transform_vector(const Vec3& v) const {
    return {rows[0].x * v.x + rows[0].y * v.y + rows[0].z * v.z,
            rows[1].x * v.x + rows[1].y * v.y + rows[1].z * v.z,
            rows[2].x * v.x + rows[2].y * v.y + rows[2].z * v.z};
  }

  float determinant() const;
};

// a * b: apply b first, then a.
Affine3 operator*(const Affine3& a, const Affine3& b);

// The inverse; for a singular transform (zero-scale bone) the result is not
// finite, which callers detect with is_finite() rather than a check here,
// so the hot path stays branch-free.
Affine3 inverse(const Affine3& m);

bool is_finite(const Affine3& m);

}  // namespace sinew
