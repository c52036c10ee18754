// Where a character stands and how it is looked at, by default: the
// conventions `sinew-editor render`, the editor window and the demo share.
// Nothing is re-oriented; these read the model's own axes.
//
// * Rest bounds: the model skinned at its skeleton's rest pose.
// * Up axis: whichever of Y and Z has the larger rest-bounds extent (glTF
//   characters are Y-up, Cal3D ones usually Z-up). Front: +Z for Y-up
//   models, -Y for Z-up models; right: +X in both (the image's right-hand
//   side when the camera looks back along -front with that up).
// * Instances, in one of two layouts, `spacing` = 1.2 * (largest rest
//   extent): kRow moves instance i by i * spacing along +X; kGrid has
//   cols = ceil(sqrt(N)) columns, instance i in column i % cols (along +X)
//   and row i / cols along the ground's other axis, away from the default
//   camera (-front: +Y for Z-up models, -Z for Y-up). In both, instance i
//   plays its clip 0.37 s * i later than instance 0.
// * Ground: a quad (2 triangles) at the rest bounds' lowest up coordinate,
//   centred on the layout (the box of every instance's rest bounds) and
//   reaching 50 * the character's height (its rest extent along up) plus
//   half the layout's diagonal along the ground from that centre, so it
//   covers every instance and fills the view to the horizon.
// * Camera: looks at the centre of a box from the front, slightly above,
//   far enough that the box's sphere fits the smaller of the two fields of
//   view, fovy 40 degrees. Light: a point light above-front-right of it.
#pragma once

#include <cstdint>

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
// The character's height: its rest extent along the up axis (at least
// 1e-3, so a flat model still gets sizes derived from it).
float character_height(const Aabb& rest);
// Soft lighting sized by the character, so the same default suits a model
// in centimetres and one in metres: ambient occlusion reaches half its
// height (the ground darkens around its feet and its own creases darken,
// while a neighbour a body length away does not), and the sphere light
// the tools suggest for soft shadows has 0.3 of its height as radius.
float default_ao_radius(const Aabb& rest);
float suggested_light_radius(const Aabb& rest);
// How instances are laid out: a row along +X, or a grid (above).
enum class Layout : std::uint8_t { kRow, kGrid };
inline constexpr const char* kLayoutNames[] = {"row", "grid"};  // by Layout, as options spell them
// The layout's columns for `instances` instances: all of them in a row,
// ceil(sqrt(instances)) in a grid.
int layout_columns(int instances, Layout layout);
// Instance `index`'s placement (model -> world) among `instances`, and its
// clip time offset (the same in both layouts).
Affine3 instance_placement(const Aabb& rest, int index, int instances = 1, Layout layout = Layout::kRow);
double instance_time_offset(int index);
// The box of every instance's rest bounds, placed.
Aabb layout_bounds(const Aabb& rest, int instances, Layout layout = Layout::kRow);
// The ground quad under `rest` sized for `instances` instances laid out by
// `layout`, in world space.
rt::StaticMeshDesc ground_plane_for(const Aabb& rest, int instances, Layout layout = Layout::kRow);
rt::StaticMeshDesc ground_plane_for(const Model& model, int instances = 1, Layout layout = Layout::kRow);
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
