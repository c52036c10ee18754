// The API's plain value types <-> Sinew's internal math types.
#pragma once

#include "runtime/math/affine.h"
#include "runtime/math/types.h"
#include "sinew/math.h"

namespace sinew::api::detail {

inline Vec3 to_internal(const Float3& v) { return {v.x, v.y, v.z}; }
inline Float3 to_api(const Vec3& v) { return {v.x, v.y, v.z}; }

inline Affine3 to_internal(const Matrix3x4& m) {
  Affine3 a;
  for (int r = 0; r < 3; ++r) a.rows[static_cast<std::size_t>(r)] = Vec4(m.m[r][0], m.m[r][1], m.m[r][2], m.m[r][3]);
  return a;
}

inline Matrix3x4 to_api(const Affine3& a) {
  Matrix3x4 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m.m[r][c] = a(r, c);
  }
  return m;
}

}  // namespace sinew::api::detail
