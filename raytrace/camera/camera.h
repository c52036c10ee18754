// PinholeCamera: the camera convention every tool and test relies on
// (issue 4, pinned by a test):
//   forward = normalize(target - eye); right = normalize(cross(forward, up));
//   up' = cross(right, forward); pixel (x, y), y = 0 the top row, shoots along
//   normalize(forward + sx*tan(fovy/2)*aspect*right + sy*tan(fovy/2)*up')
//   with sx = 2(x+0.5)/W - 1, sy = 1 - 2(y+0.5)/H, aspect = W/H.
#pragma once

#include "runtime/core/expected.h"
#include "runtime/math/ray.h"
#include "runtime/math/types.h"

namespace sinew::rt {

struct CameraDesc {
  Vec3 eye{0.0f, 1.0f, 4.0f};
  Vec3 target{0.0f, 1.0f, 0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float fovy_degrees = 45.0f;
};

class PinholeCamera {
 public:
  // Errors (kInvalidArgument naming the field): non-finite values, eye ==
  // target, up parallel to the view direction, fovy outside (0, 180), a size
  // below 1x1.
  static Expected<PinholeCamera> create(const CameraDesc& desc, int width, int height);

  // The primary ray through pixel (x, y)'s centre: origin at the eye, unit
  // direction, t in [0, inf).
  Ray ray(int x, int y) const { return ray_at(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f); }
  // The ray through a continuous image position (pixel corners at integers).
  Ray ray_at(float px, float py) const;

  int width() const { return width_; }
  int height() const { return height_; }
  const Vec3& eye() const { return eye_; }
  const Vec3& forward() const { return forward_; }
  const Vec3& right() const { return right_; }
  const Vec3& up() const { return up_; }

 private:
  Vec3 eye_{0.0f};
  Vec3 forward_{0.0f, 0.0f, -1.0f};
  Vec3 right_{1.0f, 0.0f, 0.0f};
  Vec3 up_{0.0f, 1.0f, 0.0f};
  float tan_half_fovy_ = 1.0f;
  float aspect_ = 1.0f;
  int width_ = 1;
  int height_ = 1;
};

}  // namespace sinew::rt
