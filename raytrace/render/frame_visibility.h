// The rays a render traces, as Scene::prepare_frame's cull reads them
// (scene/visibility.h): the camera's image and, with shadows, its lights.
#pragma once

#include "raytrace/camera/camera.h"
#include "raytrace/render/render_settings.h"
#include "raytrace/scene/visibility.h"

namespace sinew::rt {

// What Renderer::render(scene, camera, settings, ...) traces: camera rays
// through the image (its corners, which hold every pixel centre) and, with
// settings.shadows, shadow rays to settings.lights (or settings.light).
FrameVisibility frame_visibility(const PinholeCamera& camera, const RenderSettings& settings);

}  // namespace sinew::rt
