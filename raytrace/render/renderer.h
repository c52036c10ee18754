// Renderer: primary rays, shadow rays and diffuse shading over image tiles
// in parallel (paper section 4.1), writing only the outputs (AOVs) the
// caller asks for.
//
// Each tile runs the whole frame for its pixels: nearest hits, surfaces,
// one shadow ray per hit that faces the light, shading and the AOVs. The
// tile's hits and surfaces stay in cache from one step to the next (three
// image-wide passes spent a third of the frame re-reading and re-deriving
// them). The phases ("trace primary", "trace shadow", "shade") are timed per
// tile and the render's wall time is split in their proportion. Tiles are
// fixed squares processed in any order; every pixel's result depends only on
// the scene, so images are identical for any thread count.
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
