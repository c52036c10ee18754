#include "raytrace/render/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "raytrace/render/output/output_planes.h"
#include "raytrace/render/render_checks.h"
#include "raytrace/render/stages/tile_stages.h"
#include "raytrace/render/tile_scratch.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::rt {
namespace {

using Clock = std::chrono::steady_clock;

double nanoseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::nano>(to - from).count();
}

// Per tile: time spent in each phase and what it counted.
struct TileRecord {
  TraversalCounters primary;
  TraversalCounters shadow;
  std::uint64_t hits = 0;
  std::uint64_t shadowed = 0;
  TraversalCounters ao;
  std::uint64_t ao_occluded = 0;
  double primary_ns = 0.0;
  double shadow_ns = 0.0;
  double ao_ns = 0.0;
  double shade_ns = 0.0;
};

// One tile, stage by stage (render/stages/tile_stages.h), timing each phase.
void render_tile(const Scene& scene, const PinholeCamera& camera, const RenderSettings& settings,
                 std::span<const Light> lights, const TracePlan& plan, const OutputPlanes& out, const Tile& tile,
                 TileRecord& record) {
  TileScratch& s = tile_scratch();
  s.prepare(tile, plan);
  const auto t0 = Clock::now();
  generate_camera_rays(camera, s);
  trace_primary(scene, camera, settings.triangle_test, s, record.primary);
  const auto t1 = Clock::now();
  for (std::size_t b = 0; b < s.lanes / kBlockLanes; ++b) {
    record.hits += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(s.block_hits[b])));
  }
  if (out.want_surface()) reconstruct_surfaces(scene, surface_settings(settings, camera, out), s);
  LightRayWork light_work;
  if (out.want_light_rays()) trace_light_rays(scene, settings, lights, s, light_work);
  shade_and_write(settings, lights, out, s);
  const auto t3 = Clock::now();
  record.primary_ns = nanoseconds(t0, t1);
  record.shadow = light_work.shadow;
  record.ao = light_work.ao;
  record.shadowed = light_work.shadowed;
  record.ao_occluded = light_work.ao_occluded;
  record.shadow_ns = light_work.shadow_ns;
  record.ao_ns = light_work.ao_ns;
  record.shade_ns = nanoseconds(t1, t3) - light_work.shadow_ns - light_work.ao_ns;
}

}  // namespace

Expected<RenderStats> Renderer::render(const Scene& scene, const PinholeCamera& camera,
                                       const RenderSettings& settings, const FrameBuffers& buffers,
                                       JobSystem& jobs, PhaseTimers* timers) {
  if (buffers.width != camera.width() || buffers.height != camera.height()) {
    return invalid_argument("buffers.width x height",
                            std::to_string(buffers.width) + "x" + std::to_string(buffers.height),
                            "differs from the camera's image size");
  }
  SINEW_RETURN_IF_ERROR(check_ray_layout(settings));
  SINEW_ASSIGN_OR_RETURN(const std::span<const Light> lights, checked_lights(settings));
  SINEW_ASSIGN_OR_RETURN(const OutputPlanes out, output_planes(buffers, lights.size()));
  const int tile = settings.tile_size;
  const int tiles_x = (buffers.width + tile - 1) / tile;
  const int tiles_y = (buffers.height + tile - 1) / tile;
  std::vector<TileRecord> records(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));

  const auto start = Clock::now();
  const TracePlan plan = make_trace_plan(scene, camera, settings);
  jobs.parallel_for_tiles(buffers.width, buffers.height, tile, [&](const Tile& t) {
    render_tile(scene, camera, settings, lights, plan, out, t, records[static_cast<std::size_t>(t.index)]);
  });
  const double wall_ms = ms_since(start);

  // Tile order keeps the sums deterministic.
  RenderStats stats;
  double primary_ns = 0.0, shadow_ns = 0.0, ao_ns = 0.0, shade_ns = 0.0;
  for (const TileRecord& r : records) {
    stats.primary += r.primary;
    stats.shadow += r.shadow;
    stats.ao += r.ao;
    stats.primary_hits += r.hits;
    stats.shadowed += r.shadowed;
    stats.ao_occluded += r.ao_occluded;
    primary_ns += r.primary_ns;
    shadow_ns += r.shadow_ns;
    ao_ns += r.ao_ns;
    shade_ns += r.shade_ns;
  }
  stats.primary_rays = static_cast<std::uint64_t>(buffers.width) * static_cast<std::uint64_t>(buffers.height);
  stats.shadow_rays = stats.shadow.rays;
  stats.ao_rays = stats.ao.rays;
  // The phases interleave within each tile: the wall time of the whole
  // render is split in proportion to the time the tiles spent in each.
  const double busy_ns = primary_ns + shadow_ns + ao_ns + shade_ns;
  if (busy_ns > 0.0) {
    stats.trace_primary_ms = wall_ms * primary_ns / busy_ns;
    stats.trace_shadow_ms = wall_ms * shadow_ns / busy_ns;
    stats.trace_ao_ms = wall_ms * ao_ns / busy_ns;
    stats.shade_ms = wall_ms * shade_ns / busy_ns;
  } else {
    stats.shade_ms = wall_ms;
  }

  if (timers) {
    timers->record("trace primary", stats.trace_primary_ms);
    timers->record("trace shadow", stats.trace_shadow_ms);
    if (settings.ao_rays > 0) timers->record("trace ao", stats.trace_ao_ms);
    timers->record("shade", stats.shade_ms);
  }
  return stats;
}

}  // namespace sinew::rt
