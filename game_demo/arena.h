// The demo arena: a checkered ground (y = 0, Y up, metres), box obstacles
// and one point light. The ground and the boxes become two static meshes
// whose kd-trees the ray tracer builds once; characters walk between the
// boxes and shadow the ground, the boxes and each other.
#pragma once

#include <cstdint>
#include <vector>

#include "raytrace/scene/scene.h"
#include "runtime/math/aabb.h"

namespace sinew::demo {

struct Arena {
  std::vector<Aabb> obstacles;
  std::vector<Vec3> obstacle_colors;  // linear RGB, one per obstacle
  Vec3 light_position{6.0f, 12.0f, 4.0f};
  float ground_half_size = 16.0f;  // the floor spans [-h, h] in x and z
  float walk_half_size = 12.0f;    // characters stay within [-w, w]

  // Deterministic for a seed (own float conversion, no std distributions):
  // `obstacle_count` boxes, none within 3 m of the centre where the
  // characters start.
  static Arena generate(std::uint32_t seed, int obstacle_count);

  // The floor as checker tiles of `tile` metres (two materials), and the
  // boxes (10 triangles each, no bottom face, one material per box) when
  // there are any. The floor is a mesh of its own because its box is its
  // plane: rays that leave it upwards (area light samples, ambient
  // occlusion) never enter it, while with the boxes in one mesh they would
  // walk its tree (render/stages/stage_support.h slack_clearance).
  std::vector<rt::StaticMeshDesc> static_meshes(float tile = 2.0f) const;
};

}  // namespace sinew::demo
