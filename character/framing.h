// Where a character stands and how it is looked at, by default: the
// conventions `sinew-editor render`, the editor window and the demo share.
// Nothing is re-oriented; these read the model's own axes.
//
// * Rest bounds: the model skinned at its skeleton's rest pose.
// * Up axis: whichever of Y and Z has the larger rest-bounds extent (glTF
//   characters are Y-up, Cal3D ones usually Z-up). Front: +Z for Y-up
//   models, -Y for Z-up models; right: +X in both (the image's right-hand
//   side when the camera looks back along -front with that up).
// * Instances: instance i is moved by i * 1.2 * (largest rest extent) along
//   +X and plays its clip 0.37 s * i later than instance 0.
// * Ground: a quad (2 triangles) at the rest bounds' lowest up coordinate,
//   reaching far beyond them.
// * Camera: looks at the centre of a box from the front, slightly above,
//   far enough that the box's sphere fits the smaller of the two fields of
//   view, fovy 40 degrees. Light: a point light above-front-right of it.
#pragma once

#include "character/model.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/render_settings.h"
#include "raytrace/scene/scene.h"
#include "runtime/cli/option_values.h"
#include "runtime/math/aabb.h"

namespace sinew::character {

// The bounds of the model's vertices at rest (empty when the rest pose
// cannot be computed).
Aabb rest_bounds(const Model& model);
// 1 (Y) or 2 (Z).
int up_axis_of(const Aabb& rest);
// Instance i's placement and clip time offset.
Affine3 instance_placement(const Aabb& rest, int index);
double instance_time_offset(int index);
// The ground quad under `rest` sized for `instances` instances, in world space.
rt::StaticMeshDesc ground_plane_for(const Aabb& rest, int instances);
rt::StaticMeshDesc ground_plane_for(const Model& model, int instances = 1);
// The bounds of every instance's skinned vertices (after prepare_frame).
Aabb posed_bounds(const rt::Scene& scene);
// The default camera framing `box` and the default point light.
rt::CameraDesc default_camera(const Aabb& box, int up, int width, int height);
// The same for an image `aspect` (width / height) times as wide as it is high.
rt::CameraDesc default_camera(const Aabb& box, int up, float aspect);
Vec3 default_light(const Aabb& box, int up);
// The light a tool's --light typed (cli::parse_light).
rt::Light light_from_option(const cli::LightOption& option);

}  // namespace sinew::character
