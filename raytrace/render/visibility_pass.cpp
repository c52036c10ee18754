// Renderer::render_visibility: the light rays of render() traced from a
// host's own surfaces (render/host_surfaces.h) instead of from camera hits.
// Each tile's surfaces are filled from the host's buffers, then the stages
// render() runs after its hits take over unchanged: trace_light_rays, then
// the one mask writer (render/stages/tile_stages.h).
#include <bit>
#include <chrono>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "raytrace/render/output/output_planes.h"
#include "raytrace/render/render_checks.h"
#include "raytrace/render/renderer.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/render/trace_plan.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {
namespace {

// A normal this close to unit length (squared) is taken as it is: float
// unit vectors are, and normalising them again would move their last bits
// off the ones the host (or Sinew's own surfaces) computed.
constexpr float kUnitLengthTolerance = 1e-5f;

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The host's surface buffers as planes, checked as output_plane checks an
// output (size, pitch, alignment); they are only read.
struct SurfacePlanes {
  OutputPlane<Vec3> position;
  OutputPlane<Vec3> normal;
  OutputPlane<float> position_error;  // not wanted: offset below
  float offset = 0.0f;                // the push along the normal, world units
};

template <class T>
Expected<OutputPlane<T>> input_plane(std::span<const T> span, std::size_t pitch, int width, int height,
                                     std::string_view name) {
  // OutputPlane holds a writable pointer; this pass never writes through it.
  return output_plane(std::span<T>(const_cast<T*>(span.data()), span.size()), pitch, 1, width, height, name);
}

Expected<SurfacePlanes> surface_planes(const Scene& scene, const HostSurfaces& surfaces) {
  const int w = surfaces.width;
  const int h = surfaces.height;
  if (w < 1 || h < 1) {
    return invalid_argument("surfaces.width x height", std::to_string(w) + "x" + std::to_string(h),
                            "must be at least 1x1");
  }
  if (surfaces.position.empty()) return invalid_argument("surfaces.position", "empty", "a position per pixel is required");
  if (surfaces.normal.empty()) return invalid_argument("surfaces.normal", "empty", "a normal per pixel is required");
  const HostSurfaces::RowPitches& pitch = surfaces.row_pitch;
  SurfacePlanes planes;
  SINEW_ASSIGN_OR_RETURN(planes.position, input_plane(surfaces.position, pitch.position, w, h, "surfaces.position"));
  SINEW_ASSIGN_OR_RETURN(planes.normal, input_plane(surfaces.normal, pitch.normal, w, h, "surfaces.normal"));
  SINEW_ASSIGN_OR_RETURN(planes.position_error, input_plane(surfaces.position_error, pitch.position_error, w, h,
                                                            "surfaces.position_error"));
  if (!std::isfinite(surfaces.normal_offset)) {
    return invalid_argument("surfaces.normal_offset", std::to_string(surfaces.normal_offset), "must be finite");
  }
  planes.offset = surfaces.normal_offset;
  if (planes.offset < 0.0f) {
    const Aabb& world = scene.world_bounds();
    planes.offset = world.is_empty() ? 0.0f : kAutomaticOffsetScale * glm::length(world.upper - world.lower);
  }
  return planes;
}

// The masks' planes: only the shadow and ambient occlusion masks, at least
// one of them, the surfaces' size.
Expected<OutputPlanes> mask_planes(const FrameBuffers& masks, const HostSurfaces& surfaces, std::size_t lights) {
  if (masks.width != surfaces.width || masks.height != surfaces.height) {
    return invalid_argument("masks.width x height", std::to_string(masks.width) + "x" + std::to_string(masks.height),
                            "differs from the surfaces' " + std::to_string(surfaces.width) + "x" +
                                std::to_string(surfaces.height));
  }
  const std::pair<bool, const char*> others[] = {
      {!masks.color_rgba8.empty(), "masks.color_rgba8"}, {!masks.color_rgba32f.empty(), "masks.color_rgba32f"},
      {!masks.depth.empty(), "masks.depth"},             {!masks.normal.empty(), "masks.normal"},
      {!masks.triangle_id.empty(), "masks.triangle_id"}, {!masks.instance_id.empty(), "masks.instance_id"},
      {!masks.uv.empty(), "masks.uv"},                   {!masks.barycentric.empty(), "masks.barycentric"},
      {!masks.material_id.empty(), "masks.material_id"},
  };
  for (const auto& [given, name] : others) {
    if (given) return invalid_argument(name, "a buffer", "the visibility of a host's surfaces writes only the masks");
  }
  if (masks.shadow.empty() && masks.ambient_occlusion.empty()) {
    return invalid_argument("masks.shadow, masks.ambient_occlusion", "both empty", "at least one mask is needed");
  }
  return output_planes(masks, lights);
}

// Tile s's surfaces from the host's pixels: position, the normal as both
// geometric and shading normal, the rounding bound that makes the stages'
// push-off (offset_origin) move by the offset, and which lanes have one.
void fill_surfaces(const SurfacePlanes& in, TileScratch& s) {
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    std::uint32_t hits = 0;
    for (int lane = 0; lane < kBlockLanes; ++lane) {
      const std::size_t k = b * kBlockLanes + static_cast<std::size_t>(lane);
      // Lanes without a surface hold finite values: the stages compute
      // eight lanes at a time and mask the results.
      s.px[k] = s.py[k] = s.pz[k] = 0.0f;
      s.gx[k] = s.gy[k] = 0.0f;
      s.gz[k] = 1.0f;
      s.error[k] = 0.0f;
      s.triangle[k] = s.instance[k] = kInvalidId;
      if (!(s.block_pixels[b] >> lane & 1u)) continue;
      const int x = s.block_x0(b) + lane % kBlockWidth;
      const int y = s.block_y0(b) + lane / kBlockWidth;
      const Vec3 p = *in.position.at(x, y);
      Vec3 n = *in.normal.at(x, y);
      const float length2 = glm::dot(n, n);
      if (!finite(p) || !finite(n) || !(length2 > 0.0f) || !std::isfinite(length2)) continue;
      if (std::fabs(length2 - 1.0f) > kUnitLengthTolerance) n /= std::sqrt(length2);
      // offset_origin moves by error (|nx| + |ny| + |nz|) along n.
      const float error =
          in.position_error.wanted() ? *in.position_error.at(x, y)
                                     : in.offset / (std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z));
      if (!(error >= 0.0f) || !std::isfinite(error)) continue;
      s.px[k] = p.x;
      s.py[k] = p.y;
      s.pz[k] = p.z;
      s.gx[k] = s.nx[k] = n.x;
      s.gy[k] = s.ny[k] = n.y;
      s.gz[k] = s.nz[k] = n.z;
      s.error[k] = error;
      hits |= 1u << lane;
    }
    s.block_hits[b] = static_cast<std::uint8_t>(hits);
    s.block_on_character[b] = 0;  // the host's surfaces are none of Sinew's characters
  }
}

struct TileWork {
  LightRayWork rays;
  std::uint64_t surfaces = 0;
};

}  // namespace

Expected<RenderStats> Renderer::render_visibility(const Scene& scene, const HostSurfaces& surfaces,
                                                  const RenderSettings& settings, const FrameBuffers& masks,
                                                  JobSystem& jobs, PhaseTimers* timers) {
  SINEW_RETURN_IF_ERROR(check_ray_layout(settings));
  SINEW_ASSIGN_OR_RETURN(const std::span<const Light> lights, checked_lights(settings));
  SINEW_ASSIGN_OR_RETURN(const SurfacePlanes in, surface_planes(scene, surfaces));
  SINEW_ASSIGN_OR_RETURN(const OutputPlanes out, mask_planes(masks, surfaces, lights.size()));

  // The host's pixels are no camera's: no camera mask, and no split of fine
  // character hits (its surfaces lie on no triangle of Sinew's).
  TracePlan plan = plan_for_packet_rays(settings.packet_rays);
  plan.shadow_mask = settings.shadow_mask;
  plan.split_fine_shadows = false;

  const int tile = settings.tile_size;
  const int tiles_x = (surfaces.width + tile - 1) / tile;
  const int tiles_y = (surfaces.height + tile - 1) / tile;
  std::vector<TileWork> work(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));
  const float scene_magnitude = top_level_magnitude(scene);
  const auto start = std::chrono::steady_clock::now();
  jobs.parallel_for_tiles(surfaces.width, surfaces.height, tile, [&](const Tile& t) {
    TileWork& record = work[static_cast<std::size_t>(t.index)];
    TileScratch& s = tile_scratch();
    s.prepare(t, plan);
    fill_surfaces(in, s);
    s.scene_magnitude = scene_magnitude;
    for (std::size_t b = 0; b < s.blocks(); ++b) {
      record.surfaces += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(s.block_hits[b])));
    }
    trace_light_rays(scene, settings, lights, s, record.rays);
    const OutputPlanes& staged = s.staging.stage(out, s.tile);
    write_visibility_masks(settings, lights, staged, s);
    s.staging.flush(out);
  });
  const double wall_ms = ms_since(start);

  // Tile order keeps the sums deterministic; the wall time is split
  // between the two kinds of rays in proportion to the tiles' time in each.
  RenderStats stats;
  double shadow_ns = 0.0, ao_ns = 0.0;
  for (const TileWork& r : work) {
    stats.primary_hits += r.surfaces;
    stats.shadow += r.rays.shadow;
    stats.ao += r.rays.ao;
    stats.shadowed += r.rays.shadowed;
    stats.ao_occluded += r.rays.ao_occluded;
    shadow_ns += r.rays.shadow_ns;
    ao_ns += r.rays.ao_ns;
  }
  stats.shadow_rays = stats.shadow.rays;
  stats.ao_rays = stats.ao.rays;
  const double traced_ns = shadow_ns + ao_ns;
  stats.trace_shadow_ms = traced_ns > 0.0 ? wall_ms * shadow_ns / traced_ns : 0.0;
  stats.trace_ao_ms = traced_ns > 0.0 ? wall_ms * ao_ns / traced_ns : 0.0;
  stats.shade_ms = wall_ms - stats.trace_shadow_ms - stats.trace_ao_ms;
  if (timers) {
    timers->record("trace shadow", stats.trace_shadow_ms);
    if (settings.ao_rays > 0) timers->record("trace ao", stats.trace_ao_ms);
  }
  return stats;
}

}  // namespace sinew::rt
