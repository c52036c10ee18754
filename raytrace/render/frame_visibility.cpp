#include "raytrace/render/frame_visibility.h"

#include <algorithm>
#include <cmath>

namespace sinew::rt {

namespace {

// How far the light reaches from its position: a sphere's radius, the
// rectangle's half diagonals' bound.
float area_radius(const Light& light) {
  switch (light.kind) {
    case Light::Kind::kPoint: return light.radius;
    case Light::Kind::kRect: return 0.5f * (glm::length(light.edge_u) + glm::length(light.edge_v)) * (1.0f + 0x1.0p-10f);
    case Light::Kind::kDirectional: return 0.0f;
  }
  return 0.0f;
}

}  // namespace

FrameVisibility frame_visibility(const PinholeCamera& camera, const RenderSettings& settings) {
  FrameVisibility view;
  view.eye = camera.eye();
  view.forward = camera.forward();
  view.right = camera.right();
  view.up = camera.up();
  const float w = static_cast<float>(camera.width()), h = static_cast<float>(camera.height());
  view.half_width = std::max(std::fabs(camera.right_offset(0.0f)), std::fabs(camera.right_offset(w)));
  view.half_height = std::max(std::fabs(camera.up_offset(0.0f)), std::fabs(camera.up_offset(h)));
  view.shadows = settings.shadows;
  view.ao_reach = settings.ao_rays > 0 ? settings.ao_radius : 0.0f;
  const std::span<const Light> lights = settings.lights.empty() ? std::span<const Light>(&settings.light, 1)
                                                                : settings.lights;
  view.light_count = static_cast<std::uint32_t>(std::min(lights.size(), kMaxViewLights));
  for (std::uint32_t l = 0; l < view.light_count; ++l) {
    const Light& light = lights[l];
    view.lights[l] = {light.kind == Light::Kind::kDirectional ? ViewLight::Kind::kDirectional : ViewLight::Kind::kPoint,
                      light.position, light.direction, area_radius(light), light.angular_radius};
  }
  // The renderer refuses more lights than it shades; past kMaxViewLights
  // the view keeps its shadows from culling anything rather than guess.
  if (lights.size() > kMaxViewLights) view.light_count = kMaxViewLights + 1;
  return view;
}

}  // namespace sinew::rt
