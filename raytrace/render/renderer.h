// Renderer: primary rays, shadow rays and diffuse shading over image tiles in
// parallel (paper section 4.1), writing only the outputs (AOVs) the caller
// asks for. Each tile runs the whole frame for its pixels, so its hits and
// surfaces stay in cache from one stage to the next; the phases are timed per
// tile and the wall time split in their proportion. Every pixel depends only
// on the scene: images are identical for any thread count.
#pragma once

#include "raytrace/camera/camera.h"
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
  // Errors: kInvalidArgument when a buffer's size does not match
  // width x height (or its row pitch), a row pitch is too small or
  // misaligned, the camera's size differs from the buffers', the tile size
  // is below 1, or there are more than kMaxLights lights.
  Expected<RenderStats> render(const Scene& scene, const PinholeCamera& camera,
                               const RenderSettings& settings, const FrameBuffers& buffers,
                               JobSystem& jobs, PhaseTimers* timers = nullptr);
};

}  // namespace sinew::rt
