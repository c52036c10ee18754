// The shadow and ambient occlusion rays of a tile's hits, light by light:
// one aimed shadow ray per hard light, rounds of samples per area light and
// for ambient occlusion (docs/RAYTRACE.md, "Soft shadows and ambient
// occlusion").
#include <algorithm>
#include <chrono>

#include "raytrace/render/stages/tile_stages.h"

namespace sinew::rt {
namespace {

using Clock = std::chrono::steady_clock;

double nanoseconds_since(Clock::time_point from) {
  return std::chrono::duration<double, std::nano>(Clock::now() - from).count();
}

void set_every_light(std::size_t lights, TileScratch& s) {
  std::fill(s.lit.begin(), s.lit.begin() + static_cast<std::ptrdiff_t>(s.lanes),
            static_cast<std::uint8_t>((1u << lights) - 1u));
}

// `n` rounds of stochastic rays of stream `stream`: round j's rays, placed
// by place(j), are traced on bit `bit` of s.lit, and each hit's open
// fraction is left in fraction[0, s.lanes). Returns the blocked rays.
template <class Place>
std::uint64_t trace_rounds(const ShadowTracer& trace, const RenderSettings& settings, int n, std::uint32_t stream,
                           int bit, float* fraction, TileScratch& s, TraversalCounters& counters, Place&& place) {
  shift_pixels(settings.sample_seed, stream, s);
  std::fill_n(fraction, s.lanes, 0.0f);
  const float weight = 1.0f / static_cast<float>(n);
  std::uint64_t blocked = 0;
  for (int j = 0; j < n; ++j) {
    set_lit_bit(bit, s);
    place(j);
    blocked += trace(bit, s, counters);
    count_unblocked(bit, weight, fraction, s);
  }
  return blocked;
}

}  // namespace

void trace_light_rays(const Scene& scene, const RenderSettings& settings, std::span<const Light> lights,
                      TileScratch& s, LightRayWork& work) {
  trace_light_rays(settings, lights, s, work, [&](int l, TileScratch& rays, TraversalCounters& counters) {
    return trace_shadow_rays(scene, settings.triangle_test, l, rays, counters);
  });
}

void trace_light_rays(const RenderSettings& settings, std::span<const Light> lights, TileScratch& s,
                      LightRayWork& work, const ShadowTracer& trace) {
  bool any_hit = false;
  for (std::size_t b = 0; b < s.blocks() && !any_hit; ++b) any_hit = s.block_hits[b] != 0;
  if (any_hit && settings.ao_rays > 0) {
    // Borrows light 0's bit of s.lit, set again below.
    const auto start = Clock::now();
    const int n = settings.ao_rays;
    work.ao_occluded += trace_rounds(trace, settings, n, kAmbientOcclusionStream, 0, s.ao_open.data(), s, work.ao,
                                     [&](int j) { place_ao_rays(settings.ao_radius, 0, j, n, s); });
    work.ao_ns += nanoseconds_since(start);
  }
  set_every_light(lights.size(), s);
  if (!any_hit || !settings.shadows) return;
  const auto start = Clock::now();
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const Light& light = lights[l];
    const int bit = static_cast<int>(l);
    if (light.is_area()) {
      const int n = settings.shadow_samples;
      work.shadowed += trace_rounds(trace, settings, n, static_cast<std::uint32_t>(l), bit,
                                    &s.light_fraction[l * s.lanes], s, work.shadow,
                                    [&](int j) { place_light_samples(light, settings.sphere_disk_steps, bit, j, n, s); });
      continue;
    }
    aim_shadow_rays(light, bit, s);
    work.shadowed += trace(bit, s, work.shadow);
  }
  work.shadow_ns += nanoseconds_since(start);
}

}  // namespace sinew::rt
