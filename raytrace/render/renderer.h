// Renderer: primary rays, shadow rays and diffuse shading over image tiles in
// parallel (paper section 4.1), writing only the outputs (AOVs) the caller
// asks for. Each tile runs the whole frame for its pixels, so its hits and
// surfaces stay in cache from one stage to the next; the phases are timed per
// tile and the wall time split in their proportion. Every pixel depends only
// on the scene: images are identical for any thread count.
#pragma once

#include "raytrace/camera/camera.h"
#include "raytrace/render/host_surfaces.h"
#include "raytrace/render/render_settings.h"
#include "raytrace/render/surface.h"
#include "raytrace/render/trace_plan.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::rt {

class Renderer {
 public:
  // Camera rays through every pixel, their hits shaded. Errors:
  // kInvalidArgument when a buffer's size does not match
  // width x height (or its row pitch), a row pitch is too small or
  // misaligned, the camera's size differs from the buffers', the tile size
  // is below 1, or there are more than kMaxLights lights.
  Expected<RenderStats> render(const Scene& scene, const PinholeCamera& camera,
                               const RenderSettings& settings, const FrameBuffers& buffers,
                               JobSystem& jobs, PhaseTimers* timers = nullptr);

  // The visibility of a host's own surfaces (hybrid rendering): the same
  // shadow and ambient occlusion rays render() traces from its hits, here
  // from each pixel of `surfaces` (render/host_surfaces.h), with Sinew's
  // scene as the only occluder. Writes only masks.shadow and
  // masks.ambient_occlusion (their size is the surfaces'); every other
  // buffer of `masks` must be empty. The masks of a pixel equal render()'s
  // for a hit at the same position, normal and rounding bound, whatever the
  // thread count. Stats count the surfaces as primary_hits and no primary
  // rays. Errors: kInvalidArgument naming the field and its value: the
  // sizes and pitches of the surfaces' and the masks' buffers, a missing
  // position or normal buffer, a non-finite normal_offset, an output other
  // than the masks, no mask requested, and the light and sampling checks
  // of render().
  Expected<RenderStats> render_visibility(const Scene& scene, const HostSurfaces& surfaces,
                                          const RenderSettings& settings, const FrameBuffers& masks,
                                          JobSystem& jobs, PhaseTimers* timers = nullptr);
};

}  // namespace sinew::rt
