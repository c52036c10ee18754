// TracePlan: how one frame traces its rays, decided once per frame from the
// scene, the camera and the settings, and read by every tile's stages
// (render/stages/). Every choice here changes speed only, never a pixel: the
// packet tests run each with and without it. docs/RAYTRACE.md, "The trace
// plan", gives the measurement behind each; docs/BENCHMARKS.md the numbers.
#pragma once

#include <cstdint>

namespace sinew::rt {

class PinholeCamera;
class Scene;
struct RenderSettings;

struct TracePlan {
  // Rays traced together (RenderSettings::packet_rays) and the region of
  // 4x2-pixel blocks a tile is laid out in (render/tile_scratch.h), which a
  // large packet covers: one block for 1 and 8 rays.
  int packet_rays = 8;
  int region_blocks_x = 1;
  int region_blocks_y = 1;
  // A region whose character hits lie on pixel-sized triangles traces their
  // shadow rays as 8x8-pixel packets (RenderSettings::split_fine_shadow_packets).
  bool split_fine_shadows = true;
  // Where some character looks fine (characters_look_fine) and shadows
  // split: the static meshes' shadow rays go in 8x8-pixel packets too, and
  // shadow packets cull with each group's own frustum
  // (LargePacketRays::group_frusta).
  bool split_static_shadows = false;
  bool shadow_group_frusta = false;
  // Where some character looks fine: camera and shadow packets clip their
  // lanes to each leaf's current box (LargePacketRays::clip_leaf_lanes).
  bool clip_leaf_lanes = false;
  // Objects whose mask shares no bit with these are left out of the camera
  // rays or the shadow rays (RenderSettings::camera_mask, shadow_mask).
  std::uint32_t camera_mask = 0xFFFFFFFFu;
  std::uint32_t shadow_mask = 0xFFFFFFFFu;
};

// Whether `packet_rays` is one RenderSettings::packet_rays accepts, and the
// region (in blocks) its packets cover: one block for 1 and 8 rays.
bool valid_packet_rays(int packet_rays);
void packet_region_blocks(int packet_rays, int& blocks_x, int& blocks_y);

// Whether some character instance's triangles come out about a pixel
// across or smaller in `camera`'s image: its world box (the union of its
// bones' boxes this frame), projected, holds at most
// kFineBoxPixelsPerTriangle pixels per triangle. The box holds more pixels
// than the character and half the triangles face away, so that is about a
// pixel or less per visible triangle. An instance whose box reaches behind
// the eye counts as coarse (its triangles near the eye are large).
inline constexpr double kFineBoxPixelsPerTriangle = 2.0;
bool characters_look_fine(const Scene& scene, const PinholeCamera& camera);

// packet_rays with its region, every other choice off (tracers that take
// the stages' rays as they are: the Embree peer of the benchmarks, tests).
TracePlan plan_for_packet_rays(int packet_rays);

// The frame's plan: the one place the choices above are made.
TracePlan make_trace_plan(const Scene& scene, const PinholeCamera& camera, const RenderSettings& settings);

}  // namespace sinew::rt
