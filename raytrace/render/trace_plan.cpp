#include "raytrace/render/trace_plan.h"

#include <algorithm>
#include <limits>

#include "raytrace/camera/camera.h"
#include "raytrace/render/render_settings.h"
#include "raytrace/scene/scene.h"

namespace sinew::rt {

bool valid_packet_rays(int packet_rays) {
  return packet_rays == 1 || packet_rays == 8 || packet_rays == 64 || packet_rays == 256 || packet_rays == 512;
}

void packet_region_blocks(int packet_rays, int& blocks_x, int& blocks_y) {
  // Regions of 4x2-pixel blocks: 8x8 pixels are 2x4 blocks, 16x16 are 4x8,
  // 32x16 are 8x8 (the grid's most, cull/grid_frusta.h).
  blocks_x = blocks_y = 1;
  if (packet_rays == 64) {
    blocks_x = 2;
    blocks_y = 4;
  } else if (packet_rays == 256) {
    blocks_x = 4;
    blocks_y = 8;
  } else if (packet_rays == 512) {
    blocks_x = 8;
    blocks_y = 8;
  }
}

bool characters_look_fine(const Scene& scene, const PinholeCamera& camera) {
  // Pixels per unit of image-plane slope, along the image's x and y.
  const float w = static_cast<float>(camera.width()), h = static_cast<float>(camera.height());
  const float across = w / (camera.right_offset(w) - camera.right_offset(0.0f));
  const float down = h / (camera.up_offset(0.0f) - camera.up_offset(h));
  for (const InstanceFrame& frame : scene.instances()) {
    Aabb box = Aabb::empty();
    for (const Aabb& b : frame.bone_world_boxes) box.extend(b);
    if (!(box.lower.x <= box.upper.x)) continue;
    float x_lo = std::numeric_limits<float>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
    bool in_front = true;
    for (int corner = 0; corner < 8 && in_front; ++corner) {
      const Vec3 p((corner & 1) ? box.upper.x : box.lower.x, (corner & 2) ? box.upper.y : box.lower.y,
                   (corner & 4) ? box.upper.z : box.lower.z);
      const Vec3 q = p - camera.eye();
      const float z = glm::dot(q, camera.forward());
      in_front = z > 0.0f;
      const float x = glm::dot(q, camera.right()) / z, y = glm::dot(q, camera.up()) / z;
      x_lo = std::min(x_lo, x);
      x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y);
      y_hi = std::max(y_hi, y);
    }
    const std::size_t triangles = scene.characters()[frame.character].mesh->triangles.size();
    if (!in_front || triangles == 0) continue;
    const double pixels = static_cast<double>((x_hi - x_lo) * across) * static_cast<double>((y_hi - y_lo) * down);
    if (pixels <= kFineBoxPixelsPerTriangle * static_cast<double>(triangles)) return true;
  }
  return false;
}

TracePlan plan_for_packet_rays(int packet_rays) {
  TracePlan plan;
  plan.packet_rays = packet_rays;
  packet_region_blocks(packet_rays, plan.region_blocks_x, plan.region_blocks_y);
  return plan;
}

TracePlan make_trace_plan(const Scene& scene, const PinholeCamera& camera, const RenderSettings& settings) {
  TracePlan plan = plan_for_packet_rays(settings.packet_rays);
  plan.camera_mask = settings.camera_mask;
  plan.shadow_mask = settings.shadow_mask;
  plan.split_fine_shadows = settings.split_fine_shadow_packets;
  const bool characters_fine = characters_look_fine(scene, camera);
  const bool fine = settings.shadows && settings.split_fine_shadow_packets && characters_fine;
  plan.split_static_shadows = fine;
  plan.shadow_group_frusta = fine;
  plan.clip_leaf_lanes = characters_fine;
  return plan;
}

}  // namespace sinew::rt
