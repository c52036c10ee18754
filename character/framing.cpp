#include "character/framing.h"

#include <algorithm>
#include <cmath>

#include "character/bake.h"
#include "raytrace/skinning/skinning.h"

namespace sinew::character {
namespace {

constexpr double kInstanceTimeStep = 0.37;  // seconds between instances' clip times
constexpr float kInstanceSpacing = 1.2f;    // x the rest bounds' largest extent
constexpr float kGroundReach = 50.0f;       // x the character's height, beyond half the layout
constexpr float kDefaultFovyDegrees = 40.0f;
constexpr float kAoRadius = 0.5f;     // x the character's height
constexpr float kLightRadius = 0.3f;  // x the character's height

Vec3 axis_vector(int axis, float sign = 1.0f) {
  Vec3 v(0.0f);
  v[axis] = sign;
  return v;
}

Vec3 front_of(int up) { return up == 1 ? axis_vector(2) : axis_vector(1, -1.0f); }

float bounding_radius(const Aabb& box) { return std::max(0.5f * glm::length(box.extent()), 1e-6f); }

}  // namespace

Aabb posed_bounds(const rt::Scene& scene) {
  Aabb box;
  for (const rt::InstanceFrame& frame : scene.instances()) {
    for (const Vec3& p : frame.positions) box.extend(p);
  }
  return box;
}

rt::CameraDesc default_camera(const Aabb& box, int up, int width, int height) {
  return default_camera(box, up, static_cast<float>(width) / static_cast<float>(height));
}

rt::CameraDesc default_camera(const Aabb& box, int up, float aspect) {
  const float radius = bounding_radius(box);
  const float half_fovy = glm::radians(0.5f * kDefaultFovyDegrees);
  const float half_fovx = std::atan(std::tan(half_fovy) * aspect);
  const float distance = 1.15f * radius / std::sin(std::min(half_fovy, half_fovx));
  const Vec3 view = glm::normalize(front_of(up) + 0.2f * axis_vector(up));
  return {box.center() + distance * view, box.center(), axis_vector(up), kDefaultFovyDegrees};
}

Vec3 default_light(const Aabb& box, int up) {
  const float radius = bounding_radius(box);
  return box.center() + radius * (2.0f * front_of(up) + 3.0f * axis_vector(up) + axis_vector(0));
}

Aabb rest_bounds(const Model& model) {
  Aabb box;
  const auto skin = rest_skinning(model, Affine3::identity());
  if (!skin.ok()) return box;
  for (std::size_t v = 0; v < model.mesh.vertex_count(); ++v) box.extend(rt::skin_point(model.mesh, v, *skin));
  return box;
}

int up_axis_of(const Aabb& rest) {
  const Vec3 e = rest.extent();
  return e.y >= e.z ? 1 : 2;
}

float character_height(const Aabb& rest) { return std::max(rest.extent()[up_axis_of(rest)], 1e-3f); }

float default_ao_radius(const Aabb& rest) { return kAoRadius * character_height(rest); }

float suggested_light_radius(const Aabb& rest) { return kLightRadius * character_height(rest); }

int layout_columns(int instances, Layout layout) {
  const int n = std::max(instances, 1);
  if (layout == Layout::kRow) return n;
  int cols = 1;
  while (cols * cols < n) ++cols;  // ceil(sqrt(n)), exactly
  return cols;
}

Affine3 instance_placement(const Aabb& rest, int index, int instances, Layout layout) {
  const Vec3 e = rest.extent();
  const float spacing = kInstanceSpacing * std::max({e.x, e.y, e.z});
  if (layout == Layout::kRow) return Affine3::translation(axis_vector(0, static_cast<float>(index) * spacing));
  const int cols = layout_columns(instances, layout);
  const int up = up_axis_of(rest);
  const float column = static_cast<float>(index % cols);
  const float row = static_cast<float>(index / cols);
  return Affine3::translation(axis_vector(0, column * spacing) - (row * spacing) * front_of(up));
}

double instance_time_offset(int index) { return kInstanceTimeStep * index; }

Aabb layout_bounds(const Aabb& rest, int instances, Layout layout) {
  Aabb box;
  for (int i = 0; i < std::max(instances, 1); ++i) {
    const Vec3 t = instance_placement(rest, i, instances, layout).translation_part();
    box.extend(rest.lower + t);
    box.extend(rest.upper + t);
  }
  return box;
}

rt::StaticMeshDesc ground_plane_for(const Aabb& rest, int instances, Layout layout) {
  const int up = up_axis_of(rest);
  const int a = (up + 1) % 3;
  const int b = (up + 2) % 3;
  const float height = character_height(rest);
  // Centred under the layout and reaching far past it, so the ground fills
  // the background of the default camera.
  const Aabb layout_box = layout_bounds(rest, instances, layout);
  const Vec3 centre = layout_box.center();
  const Vec3 extent = layout_box.extent();
  const float reach = kGroundReach * height + 0.5f * std::hypot(extent[a], extent[b]);
  rt::StaticMeshDesc ground;
  for (int corner = 0; corner < 4; ++corner) {
    Vec3 p(0.0f);
    p[up] = rest.lower[up];
    p[a] = centre[a] + ((corner & 1) ? reach : -reach);
    p[b] = centre[b] + ((corner & 2) ? reach : -reach);
    ground.positions.push_back(p);
  }
  ground.triangles = {{0, 1, 3}, {0, 3, 2}};
  ground.material_colors = {Vec3(0.5f)};
  return ground;
}

rt::StaticMeshDesc ground_plane_for(const Model& model, int instances, Layout layout) {
  return ground_plane_for(rest_bounds(model), instances, layout);
}

// --- the command --------------------------------------------------------------

rt::Light light_from_option(const cli::LightOption& option) {
  rt::Light light;
  light.kind = option.directional ? rt::Light::Kind::kDirectional : rt::Light::Kind::kPoint;
  const Vec3 xyz(option.xyz[0], option.xyz[1], option.xyz[2]);
  if (option.directional) {
    light.direction = xyz;
  } else {
    light.position = xyz;
  }
  light.color = Vec3(option.rgb[0], option.rgb[1], option.rgb[2]);
  return light;
}

}  // namespace sinew::character
