// FrameVisibility and FrameCull: which character instances a frame's rays
// can reach, so that Scene::prepare_frame skins only those
// (docs/RAYTRACE.md, "Culling whole characters").
//
// A frame traces camera rays from the eye through the image and, per light,
// shadow rays between the light and the points the camera rays hit. A
// character can be hit by a camera ray only inside the view frustum, and by
// a shadow ray only inside the light's caster volume: the hull of the light
// and the visible receivers (the frustum's part of every static mesh and of
// every character in view), or for a directional light the receivers swept
// towards it. FrameCull bounds each caster volume by a handful of planes
// (a k-DOP: a few fixed directions and a pyramid from the light around the
// receivers) and keeps a box that no plane of the frustum, or of some
// light's bound, cuts off. Every plane holds its whole volume, so the test
// never drops a character a ray can reach; a box near a plane is kept.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/math/aabb.h"
#include "runtime/math/types.h"

namespace sinew::rt {

// A light as far as shadow rays go.
struct ViewLight {
  enum class Kind : std::uint8_t { kPoint, kDirectional };
  Kind kind = Kind::kPoint;
  Vec3 position{0.0f};               // kPoint
  Vec3 direction{0.0f, 1.0f, 0.0f};  // kDirectional: towards the light (any length)
  // An area light's extent: kPoint, every point of the light lies within
  // `radius` of `position` (a sphere or rectangle light); kDirectional,
  // its rays arrive within `angular_radius` radians of `direction` (the
  // sun).
  float radius = 0.0f;
  float angular_radius = 0.0f;
};

inline constexpr std::size_t kMaxViewLights = 8;

// The rays a frame traces: camera rays eye + t * (forward + a * right + b * up)
// with t >= 0, |a| <= half_width and |b| <= half_height (a pinhole camera's
// image, camera/camera.h), and with `shadows`, one shadow ray per light
// between the light and a point a camera ray hits.
struct FrameVisibility {
  Vec3 eye{0.0f};
  Vec3 forward{0.0f, 0.0f, -1.0f};
  Vec3 right{1.0f, 0.0f, 0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float half_width = 1.0f;
  float half_height = 1.0f;
  bool shadows = true;
  std::array<ViewLight, kMaxViewLights> lights{};
  std::uint32_t light_count = 0;
  // Ambient occlusion rays: up to this long, from a point a camera ray
  // hits (0: none).
  float ao_reach = 0.0f;
};

// The cull of one frame. Use: begin(), in_view() per box, add_receivers()
// for every static mesh's box and every box in view, finish_receivers(),
// then casts_into_view() per box not in view. Keeps its scratch from frame
// to frame. Works in double; boxes are grown by `margin` (relative to the
// scene's magnitude) before every test.
class FrameCull {
 public:
  // `magnitude`: the largest |coordinate| of any box the frame tests or adds
  // as receivers. False when the view is unusable (a non-finite field, a
  // half extent not in (0, 1e6)); then nothing may be culled.
  bool begin(const FrameVisibility& view, float magnitude);

  // Whether a camera ray may reach `box`.
  bool in_view(const Aabb& box) const;

  // Adds the part of `box` inside the view frustum as surfaces that shadow
  // rays may start from.
  void add_receivers(const Aabb& box);

  // Bounds each light's caster volume from the receivers added.
  void finish_receivers();

  // Whether a shadow ray or an ambient occlusion ray may reach `box`
  // (after finish_receivers).
  bool casts_into_view(const Aabb& box) const;

  // The relative margin every box is grown by: far above the rounding of
  // skinning, ray set-up and triangle tests, far below a character.
  static constexpr double kRelativeMargin = 0x1.0p-14;

 private:
  struct Plane {
    double n[3] = {0.0, 0.0, 0.0};
    double offset = 0.0;  // a point p is inside when n . p <= offset
  };
  static bool box_outside(const Plane& plane, const double lower[3], const double upper[3]);
  void grown(const Aabb& box, double lower[3], double upper[3]) const;

  FrameVisibility view_{};
  double margin_ = 0.0;
  std::array<Plane, 4> frustum_{};
  std::vector<std::array<double, 3>> receivers_;  // corners of the visible receivers
  // Per light, its planes in planes_[light_begin_[l], light_begin_[l + 1]).
  std::vector<Plane> planes_;
  std::array<std::uint32_t, kMaxViewLights + 1> light_begin_{};
  bool shadows_ = false;
};

}  // namespace sinew::rt
