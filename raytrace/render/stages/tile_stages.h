// The stages of one tile's frame, each over the tile's 4x2-pixel blocks in
// structure-of-arrays form (render/tile_scratch.h), eight lanes at a time:
//
//   generate_camera_rays -> trace_primary -> reconstruct_surfaces
//   -> per light: aim_shadow_rays -> trace_shadow_rays
//   -> shade_and_write
//
// or, on a host's own surfaces (render/host_surfaces.h), the surfaces
// filled from its buffers -> trace_light_rays -> write_visibility_masks.
//
// Renderer::render runs them per tile; the Embree peer of the benchmarks
// runs the same stages with its own two trace stages, so camera rays,
// surfaces, shadow-ray origins and shading are the same code for both.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include "raytrace/camera/camera.h"
#include "raytrace/render/output/output_planes.h"
#include "raytrace/render/render_settings.h"
#include "raytrace/render/surface.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/scene/scene.h"
#include "raytrace/cull/static_tiles.h"

namespace sinew::rt {

// Unit primary directions of every lane (lanes outside the image too, so
// the arithmetic stays finite); bit-identical to PinholeCamera::ray.
void generate_camera_rays(const PinholeCamera& camera, TileScratch& s);

// The cone (cull/static_tiles.h) holding every camera ray of `tile`'s
// pixels: the rays through its corner pixels span the others (a pinhole
// camera's direction is affine in the pixel before it is normalised, which
// does not move a ray). And the one holding every shadow ray
// aim_shadow_rays bounded from a point light (to the corners of
// s.shadow_ends); without a point light none (nothing is culled).
TileCone camera_tile_cone(const PinholeCamera& camera, const Tile& tile);
TileCone shadow_tile_cone(const TileScratch& s);

// Nearest hits of the tile's pixels, with the tile's primary rays culled
// against the top level as one bound and each packet's again
// (cull/ray_bound.h), s.plan.packet_rays at a time: 1 is one single-ray
// query per pixel, no culling; 64, 256 and 512 take one packet per region.
// Fills t, u, v, triangle, instance and block_hits.
void trace_primary(const Scene& scene, const PinholeCamera& camera, TriangleTest test, TileScratch& s,
                   TraversalCounters& counters);

// trace_primary's way for a tile whose rays reach only `tile`'s gathered
// static triangles (gather_static_tile): the tile's blocks as packets of
// the core against them. Fills what trace_primary fills; counts object
// visits and triangle tests, not rays.
void intersect_static_tile(const StaticTile& tile, const PinholeCamera& camera, TileScratch& s,
                           TraversalCounters& counters);

// What reconstruct_surfaces needs beside the hits.
struct SurfaceSettings {
  Vec3 default_albedo{0.7f};  // RenderSettings::default_albedo
  float pixel_spread = 0.0f;  // PinholeCamera::pixel_spread: how fast a pixel's footprint grows
  bool textures = true;       // RenderSettings::textures
  bool hit_attributes = false;  // fill s.uv_x, s.uv_y and s.material (OutputPlanes::want_hit_attributes)
};
SurfaceSettings surface_settings(const RenderSettings& settings, const PinholeCamera& camera,
                                 const OutputPlanes& out);

// The surfaces at the hits (positions, camera-facing geometric and
// shading normals, albedo, rounding bound), as surface_at computes them,
// and which hits are on characters (s.block_on_character). With textures
// on, a textured material's albedo is also multiplied by its texture at
// the hit's uv (which surface_at leaves out), from the mip level the
// pixel's footprint asks for (docs/RAYTRACE.md, "Textures").
void reconstruct_surfaces(const Scene& scene, const SurfaceSettings& settings, TileScratch& s);

// The largest |coordinate| of the scene's top level this frame, 0 for an
// empty one: TileScratch::scene_magnitude, which reconstruct_surfaces sets
// and a host's surfaces set with this.
float top_level_magnitude(const Scene& scene);

// Light `l`'s shadow rays for the hits whose surface faces it, placed lane
// by lane (s.shadow_lanes, s.shadow_lane_*); hits facing away lose bit l of
// s.lit here. A point light's rays are shadow_ray_from_light's (from the
// light, t_max 1); a directional light's leave offset_origin along the
// light (t_max inf).
void place_shadow_rays(const Light& light, int l, TileScratch& s);

// The renderer's way to the same rays, in two steps. aim_shadow_rays picks
// the lanes (and clears bit l of s.lit for hits facing away) and bounds
// where every ray ends (s.shadow_ends) without computing the rays;
// offset_shadow_rays then places them as place_shadow_rays does.
// trace_shadow_rays places aimed rays itself, and only when the bound of
// every ray the box allows reaches some object: a tile in the open pays for
// no ray.
void aim_shadow_rays(const Light& light, int l, TileScratch& s);
void offset_shadow_rays(TileScratch& s);

// The placed rays compacted into s.shadow_* in runs (s.shadow_region_begin):
// per region, the rays of its hits on characters, then those on static
// meshes, each in block order. Does nothing when they already are.
void compact_shadow_rays(TileScratch& s);

// place_shadow_rays, then compact_shadow_rays (tracers that take every ray,
// as the Embree peer of the benchmarks does).
void make_shadow_rays(const Light& light, int l, TileScratch& s);

// Traces the placed (or aimed) shadow rays one by one, as packets of eight,
// or as one large packet per region (s.plan); blocked rays clear bit l of
// s.lit. Returns how many were blocked. Packets are culled like the primary
// rays, first the tile's rays as one bound (from their ends' box when they
// are only aimed, then from the placed rays): when that reaches no object,
// nothing is placed, compacted or traced. Single rays (packet_rays 1) are
// all traced.
std::uint64_t trace_shadow_rays(const Scene& scene, TriangleTest test, int l, TileScratch& s,
                                TraversalCounters& counters);

// trace_shadow_rays' way for compacted shadow rays (s.so_*, s.sd_*, t in
// [0, s.s_tmax), a spare group past the last) that reach only `tile`'s
// gathered static triangles: as packets of the core against them. Clears
// bit l of each blocked ray's pixel and returns how many were blocked;
// counts object visits and triangle tests, not rays.
std::uint64_t occluded_static_tile(const StaticTile& tile, int l, TileScratch& s, TraversalCounters& counters);

// The stochastic rays (docs/RAYTRACE.md, "Soft shadows and ambient
// occlusion"), a round at a time: each round places one sample per hit as
// segments (s.shadows_per_lane) that trace_shadow_rays traces like any
// shadow rays, clearing bit l of s.lit where blocked; count_unblocked then
// adds the round's open rays to a per-hit fraction.
//
// shift_pixels: each hit pixel's shift of stream `stream`'s pattern
// (render/sampling/sample_pattern.h), for the rounds that follow.
void shift_pixels(std::uint32_t seed, std::uint32_t stream, TileScratch& s);
// Sample j of n of an area light (Light::is_area) per hit: from a point on
// the sphere's disk facing the hit, or on the rectangle, to the hit pushed
// off as a point light's rays end (t in [0, 1)); or, for the sun, from the
// hit pushed off along a direction within its angular radius (t unbounded).
// Hits whose surface faces away from their sample lose bit l of s.lit.
// A sphere's disk turns in steps of `disk_steps` (RenderSettings::sphere_disk_steps).
void place_light_samples(const Light& light, int disk_steps, int l, int j, int n, TileScratch& s);
// Ambient occlusion ray j of n per hit: cosine distributed about the
// camera-facing geometric normal, `radius` long (t in [0, 1) along radius
// times the unit direction), from the hit pushed off.
void place_ao_rays(float radius, int l, int j, int n, TileScratch& s);
// Sets bit l of s.lit on every lane (a round's start).
void set_lit_bit(int l, TileScratch& s);
// fraction[k] += weight for each hit k whose bit l of s.lit is set.
void count_unblocked(int l, float weight, float* fraction, const TileScratch& s);

// What trace_light_rays traced, and the time it took.
struct LightRayWork {
  TraversalCounters shadow, ao;
  std::uint64_t shadowed = 0, ao_occluded = 0;  // blocked rays
  double shadow_ns = 0.0, ao_ns = 0.0;
};

// The rays the shading and the visibility masks need from the tile's hits
// (their surfaces reconstructed): with settings.ao_rays, the ambient
// occlusion rounds (into s.ao_open); with settings.shadows, each hard
// light's shadow rays (into its bit of s.lit, which this sets for every
// light first) and each area light's sample rounds (into its span of
// s.light_fraction).
void trace_light_rays(const Scene& scene, const RenderSettings& settings, std::span<const Light> lights,
                      TileScratch& s, LightRayWork& work);

// The same with another tracer of the shadow rays (the Embree peer of the
// benchmarks), so that both trace the same rays: trace(l, s, counters)
// traces the rays aimed or placed for bit l (offset_shadow_rays and
// compact_shadow_rays make them ready), clears bit l of s.lit for each
// blocked one and returns how many were.
using ShadowTracer = std::function<std::uint64_t(int l, TileScratch& s, TraversalCounters& counters)>;
void trace_light_rays(const RenderSettings& settings, std::span<const Light> lights, TileScratch& s,
                      LightRayWork& work, const ShadowTracer& trace);

// The visibility masks of the tile's pixels into `out` (the tile's staged
// planes or the host's; each written only when wanted), from what
// trace_light_rays left: per light its bit of s.lit (a hard light) or its
// fraction of samples (an area light, with shadows on), and the open
// fraction of the ambient occlusion rays (with ao_rays). A pixel without a
// surface gets 1 everywhere. The one writer of the masks, for the camera
// path (shade_and_write) and a host's surfaces (Renderer::render_visibility).
void write_visibility_masks(const RenderSettings& settings, std::span<const Light> lights, const OutputPlanes& out,
                            const TileScratch& s);

// Diffuse shading (ambient + each unblocked light's N.L) and the requested
// outputs of the tile's pixels, through s.staging: line-aligned planes get
// whole lines by streaming stores, the others are written in place.
void shade_and_write(const RenderSettings& settings, std::span<const Light> lights, const OutputPlanes& out,
                     TileScratch& s);

}  // namespace sinew::rt
