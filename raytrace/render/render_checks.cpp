#include "raytrace/render/render_checks.h"

#include <cmath>
#include <string>

#include "raytrace/render/trace_plan.h"

namespace sinew::rt {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The sample counts, the ambient occlusion radius and every light's shape.
Status check_sampling(const RenderSettings& settings, std::span<const Light> lights) {
  if (settings.shadow_samples < 1 || settings.shadow_samples > kMaxSamples) {
    return invalid_argument("settings.shadow_samples", std::to_string(settings.shadow_samples),
                            "must be 1 to " + std::to_string(kMaxSamples));
  }
  if (settings.ao_rays < 0 || settings.ao_rays > kMaxSamples) {
    return invalid_argument("settings.ao_rays", std::to_string(settings.ao_rays),
                            "must be 0 to " + std::to_string(kMaxSamples));
  }
  const int steps = settings.sphere_disk_steps;
  if (steps != 0 && (steps < kMinSphereDiskSteps || steps > kMaxSphereDiskSteps || (steps & (steps - 1)) != 0)) {
    return invalid_argument("settings.sphere_disk_steps", std::to_string(steps),
                            "must be 0 or a power of two from " + std::to_string(kMinSphereDiskSteps) + " to " +
                                std::to_string(kMaxSphereDiskSteps));
  }
  if (settings.ao_rays > 0 && !(std::isfinite(settings.ao_radius) && settings.ao_radius > 0.0f)) {
    return invalid_argument("settings.ao_radius", std::to_string(settings.ao_radius), "must be finite and above 0");
  }
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const Light& light = lights[l];
    const std::string name = "settings.lights[" + std::to_string(l) + "]";
    if (!finite(light.position) || !finite(light.direction) || !finite(light.color)) {
      return invalid_argument(name, "a non-finite position, direction or color", "must be finite");
    }
    if (!(std::isfinite(light.radius) && light.radius >= 0.0f)) {
      return invalid_argument(name + ".radius", std::to_string(light.radius), "must be finite and at least 0");
    }
    if (!(light.angular_radius >= 0.0f && light.angular_radius < 1.5f)) {
      return invalid_argument(name + ".angular_radius", std::to_string(light.angular_radius),
                              "must be at least 0 and below 1.5 radians");
    }
    if (light.kind == Light::Kind::kDirectional && !(glm::length(light.direction) > 0.0f)) {
      return invalid_argument(name + ".direction", "0", "a directional light needs a direction");
    }
    if (light.kind == Light::Kind::kRect &&
        !(finite(light.edge_u) && finite(light.edge_v) && glm::length(glm::cross(light.edge_u, light.edge_v)) > 0.0f)) {
      return invalid_argument(name + ".edge_u, edge_v", "parallel, zero or non-finite edges",
                              "a rectangle light needs two finite edges spanning an area");
    }
  }
  return Status{};
}

}  // namespace

Expected<std::span<const Light>> checked_lights(const RenderSettings& settings) {
  const std::span<const Light> lights =
      settings.lights.empty() ? std::span<const Light>(&settings.light, 1) : settings.lights;
  if (lights.size() > kMaxLights) {
    return invalid_argument("settings.lights", std::to_string(lights.size()),
                            "at most " + std::to_string(kMaxLights) + " lights");
  }
  SINEW_RETURN_IF_ERROR(check_sampling(settings, lights));
  return lights;
}

Status check_ray_layout(const RenderSettings& settings) {
  if (!valid_packet_rays(settings.packet_rays)) {
    return invalid_argument("settings.packet_rays", std::to_string(settings.packet_rays), "must be 1, 8, 64, 256 or 512");
  }
  if (settings.tile_size < 1) {
    return invalid_argument("settings.tile_size", std::to_string(settings.tile_size), "must be at least 1");
  }
  return Status{};
}

Expected<OutputPlanes> output_planes(const FrameBuffers& buffers, std::size_t lights) {
  const int w = buffers.width;
  const int h = buffers.height;
  const FrameBuffers::RowPitches& pitch = buffers.row_pitch;
  OutputPlanes out;
  SINEW_ASSIGN_OR_RETURN(out.rgba8,
                         output_plane(buffers.color_rgba8, pitch.color_rgba8, 4, w, h, "buffers.color_rgba8"));
  SINEW_ASSIGN_OR_RETURN(out.rgba32f,
                         output_plane(buffers.color_rgba32f, pitch.color_rgba32f, 4, w, h, "buffers.color_rgba32f"));
  SINEW_ASSIGN_OR_RETURN(out.depth, output_plane(buffers.depth, pitch.depth, 1, w, h, "buffers.depth"));
  SINEW_ASSIGN_OR_RETURN(out.normal, output_plane(buffers.normal, pitch.normal, 1, w, h, "buffers.normal"));
  SINEW_ASSIGN_OR_RETURN(out.triangle,
                         output_plane(buffers.triangle_id, pitch.triangle_id, 1, w, h, "buffers.triangle_id"));
  SINEW_ASSIGN_OR_RETURN(out.instance,
                         output_plane(buffers.instance_id, pitch.instance_id, 1, w, h, "buffers.instance_id"));
  SINEW_ASSIGN_OR_RETURN(out.uv, output_plane(buffers.uv, pitch.uv, 1, w, h, "buffers.uv"));
  SINEW_ASSIGN_OR_RETURN(out.barycentric,
                         output_plane(buffers.barycentric, pitch.barycentric, 1, w, h, "buffers.barycentric"));
  SINEW_ASSIGN_OR_RETURN(out.material,
                         output_plane(buffers.material_id, pitch.material_id, 1, w, h, "buffers.material_id"));
  SINEW_ASSIGN_OR_RETURN(out.shadow, output_plane(buffers.shadow, pitch.shadow, lights, w, h, "buffers.shadow"));
  SINEW_ASSIGN_OR_RETURN(out.ambient_occlusion, output_plane(buffers.ambient_occlusion, pitch.ambient_occlusion, 1,
                                                             w, h, "buffers.ambient_occlusion"));
  return out;
}

}  // namespace sinew::rt
