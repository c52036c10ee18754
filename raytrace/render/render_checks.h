// The checks both of Renderer's entry points make before tracing anything
// (render/renderer.h): the lights and their sampling, the ray layout, and
// the host's output buffers as planes. Each error names the field and its
// value.
#pragma once

#include <cstddef>
#include <span>

#include "raytrace/render/output/output_planes.h"
#include "raytrace/render/render_settings.h"
#include "runtime/core/expected.h"

namespace sinew::rt {

// The render's lights (settings.lights, or settings.light when that is
// empty), checked: at most kMaxLights, finite, each shape valid; and the
// sample counts and ambient occlusion radius.
Expected<std::span<const Light>> checked_lights(const RenderSettings& settings);

// settings.packet_rays and settings.tile_size.
Status check_ray_layout(const RenderSettings& settings);

// The planes over every requested output of `buffers` (the shadow mask with
// one channel per light), with their sizes and pitches checked.
Expected<OutputPlanes> output_planes(const FrameBuffers& buffers, std::size_t lights);

}  // namespace sinew::rt
