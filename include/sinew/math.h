// The few value types the API exchanges, plain and layout-stable so a host
// can fill them from its own math library with a memcpy.
#pragma once

namespace sinew::api {

struct Float2 {
  float x = 0.0f;
  float y = 0.0f;
};

struct Float3 {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
};

// An affine transform as three rows [R | t]: p' = R p + t, so m[r][3] is the
// translation. Row-major 3x4, the layout of a GPU skinning palette; a
// column-major 4x4 (glm::mat4, Eigen's default) is its transpose minus the
// last row.
struct Matrix3x4 {
  float m[3][4] = {{1.0f, 0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f, 0.0f}};

  static constexpr Matrix3x4 identity() { return {}; }
  static constexpr Matrix3x4 translation(float x, float y, float z) {
    Matrix3x4 t;
    t.m[0][3] = x;
    t.m[1][3] = y;
    t.m[2][3] = z;
    return t;
  }
};

}  // namespace sinew::api
