// PinholeCamera: the camera convention every tool and test relies on
// (pinned by tests/raytrace/camera_test.cpp):
//   forward = normalize(target - eye); right = normalize(cross(forward, up));
//   up' = cross(right, forward); pixel (x, y), y = 0 the top row, shoots along
//   normalize(forward + sx*tan(fovy/2)*aspect*right + sy*tan(fovy/2)*up')
//   with sx = 2(x+0.5)/W - 1, sy = 1 - 2(y+0.5)/H, aspect = W/H.
#pragma once

#include "runtime/core/expected.h"
#include "runtime/math/float8.h"
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

  // ray_at's unit directions for eight image positions at once, lane by lane
  // bit-identical to it (the same operations in the same order).
  Vec3x8 directions_at(Float8 px, Float8 py) const {
    const Float8 sx = Float8(2.0f) * px / Float8(static_cast<float>(width_)) - Float8(1.0f);
    const Float8 sy = Float8(1.0f) - Float8(2.0f) * py / Float8(static_cast<float>(height_));
    return directions_from(sx * Float8(tan_half_fovy_) * Float8(aspect_), sy * Float8(tan_half_fovy_));
  }
  // directions_at in two steps, for callers that reuse a column's or a
  // row's offset (a tile's pixels: two divisions a pixel saved): the image
  // position's offset along right and along up, each bit-identical to
  // directions_at's lanes, and the unit directions from them.
  float right_offset(float px) const {
    return (2.0f * px / static_cast<float>(width_) - 1.0f) * tan_half_fovy_ * aspect_;
  }
  float up_offset(float py) const { return (1.0f - 2.0f * py / static_cast<float>(height_)) * tan_half_fovy_; }
  Vec3x8 directions_from(Float8 a, Float8 b) const {
    const Vec3x8 d{Float8(forward_.x) + a * Float8(right_.x) + b * Float8(up_.x),
                   Float8(forward_.y) + a * Float8(right_.y) + b * Float8(up_.y),
                   Float8(forward_.z) + a * Float8(right_.z) + b * Float8(up_.z)};
    const Float8 inv_length = Float8(1.0f) / sqrt(dot(d, d));
    return inv_length * d;
  }

  // The angle one pixel subtends at the image's centre (radians): how fast
  // a pixel's footprint grows with distance, for texture filtering.
  float pixel_spread() const { return 2.0f * tan_half_fovy_ / static_cast<float>(height_); }
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
