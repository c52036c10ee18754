#include "raytrace/camera/camera.h"

#include <cmath>
#include <cstdio>
#include <glm/gtc/constants.hpp>
#include <limits>
#include <string>

#include "runtime/core/format_number.h"

namespace sinew::rt {
namespace {

std::string format_vec(const Vec3& v) {
  return "(" + format_number(static_cast<double>(v.x)) + ", " + format_number(static_cast<double>(v.y)) + ", " +
         format_number(static_cast<double>(v.z)) + ")";
}

bool all_finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::dvec3 to_double(const Vec3& v) { return glm::dvec3(v); }

}  // namespace

Expected<PinholeCamera> PinholeCamera::create(const CameraDesc& desc, int width, int height) {
  if (!all_finite(desc.eye)) return invalid_argument("camera.eye", format_vec(desc.eye), "must be finite");
  if (!all_finite(desc.target)) {
    return invalid_argument("camera.target", format_vec(desc.target), "must be finite");
  }
  if (!all_finite(desc.up)) return invalid_argument("camera.up", format_vec(desc.up), "must be finite");
  if (!(desc.fovy_degrees > 0.0f && desc.fovy_degrees < 180.0f)) {
    return invalid_argument("camera.fovy_degrees", format_number(static_cast<double>(desc.fovy_degrees)),
                            "must lie in (0, 180)");
  }
  if (width < 1) return invalid_argument("width", std::to_string(width), "must be at least 1");
  if (height < 1) return invalid_argument("height", std::to_string(height), "must be at least 1");

  // The basis is built in double: float eye/target far apart could overflow
  // a float length, and a near-parallel up loses digits in the cross product.
  const glm::dvec3 view = to_double(desc.target) - to_double(desc.eye);
  const double view_length = glm::length(view);
  if (!(view_length > 0.0)) {
    return invalid_argument("camera.target", format_vec(desc.target), "equals camera.eye");
  }
  const glm::dvec3 forward = view / view_length;
  const glm::dvec3 up_in = to_double(desc.up);
  const glm::dvec3 side = glm::cross(forward, up_in);
  const double side_length = glm::length(side);
  // |cross| = |up| sin(angle): relative to |up|, so a tiny but valid up is fine.
  if (!(side_length > 1e-6 * glm::length(up_in))) {
    return invalid_argument("camera.up", format_vec(desc.up), "is zero or parallel to target - eye");
  }
  const glm::dvec3 right = side / side_length;
  const glm::dvec3 true_up = glm::cross(right, forward);

  PinholeCamera camera;
  camera.eye_ = desc.eye;
  camera.forward_ = Vec3(forward);
  camera.right_ = Vec3(right);
  camera.up_ = Vec3(true_up);
  const double half_fovy = static_cast<double>(desc.fovy_degrees) * glm::pi<double>() / 360.0;
  camera.tan_half_fovy_ = static_cast<float>(std::tan(half_fovy));
  camera.aspect_ = static_cast<float>(static_cast<double>(width) / static_cast<double>(height));
  camera.width_ = width;
  camera.height_ = height;
  return camera;
}

Ray PinholeCamera::ray_at(float px, float py) const {
  // Image plane at distance 1 along forward: x in [-aspect, aspect] *
  // tan(fovy/2) to the right, y in [-1, 1] * tan(fovy/2) up, y = 0 on top.
  const float sx = 2.0f * px / static_cast<float>(width_) - 1.0f;
  const float sy = 1.0f - 2.0f * py / static_cast<float>(height_);
  const Vec3 direction = forward_ + (sx * tan_half_fovy_ * aspect_) * right_ + (sy * tan_half_fovy_) * up_;
  Ray ray;
  ray.origin = eye_;
  ray.direction = glm::normalize(direction);
  ray.t_min = 0.0f;
  ray.t_max = std::numeric_limits<float>::infinity();
  return ray;
}

}  // namespace sinew::rt
