// The Embree 3 contender of `sinew-bench embree` (and of its test): an
// Embree scene over the skinned triangles a prepared rt::Scene already holds
// (Sinew's own skinning, so skinning is identical for every contender), and
// a tile-parallel renderer over Sinew's JobSystem that runs the renderer's
// own tile stages (render/stages/tile_stages.h: camera rays, surfaces, shadow-ray
// origins, shading) with Embree doing the two trace stages. Only the
// acceleration structure and the traversal differ.
//
// What differs from rt::Renderer, on purpose or for simplicity:
// - Embree's own ray packets (EmbreeWidth: single rays or 4/8/16-wide
//   packets with the coherent flag) and its own triangle test (not Sinew's
//   fast/watertight choice);
// - the vertex positions are copied into Embree's padded buffers each frame
//   (Embree may read 4 bytes past the last vertex); the copy is timed as
//   part of the build / refit.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/math/ray.h"

namespace sinew {
class JobSystem;
}

namespace sinew::bench {

enum class EmbreeMode : std::uint8_t {
  kRebuildLow,     // RTC_BUILD_QUALITY_LOW, dynamic scene, full rebuild every frame
  kRebuildMedium,  // RTC_BUILD_QUALITY_MEDIUM, full rebuild every frame
  kRefit,          // built once, then RTC_BUILD_QUALITY_REFIT: the BVH is refitted each frame
};

const char* embree_mode_name(EmbreeMode mode);

// How rays are handed to Embree: one at a time (rtcIntersect1/rtcOccluded1)
// or as packets of 4, 8 or 16 (rtcIntersectN/rtcOccludedN with
// RTC_INTERSECT_CONTEXT_FLAG_COHERENT). Primary packets are 4x1, 4x2 and
// 8x2 pixels of the tile; shadow packets take the tile's shadow rays in
// order.
enum class EmbreeWidth : std::uint8_t { k1, k4, k8, k16 };
inline constexpr EmbreeWidth kEmbreeWidths[] = {EmbreeWidth::k1, EmbreeWidth::k4, EmbreeWidth::k8,
                                                EmbreeWidth::k16};
const char* embree_width_name(EmbreeWidth width);

struct EmbreeRenderStats {
  std::uint64_t primary_hits = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t shadowed = 0;
  std::uint64_t ao_rays = 0;
  double trace_primary_ms = 0.0;
  double trace_shadow_ms = 0.0;
  double trace_ao_ms = 0.0;
  double shade_ms = 0.0;
};

// One skinned mesh the caller keeps (the query benchmark's path, which has
// no rt::Scene): its triangles, this tick's world positions, and the id its
// hits report. The spans need only live through the update.
struct EmbreeMesh {
  std::span<const std::array<std::uint32_t, 3>> triangles;
  std::span<const Vec3> positions;
  std::uint32_t id = 0;
};

class EmbreeTracer {
 public:
  // `threads`: the Embree device's build threads (the JobSystem's count, so
  // builds and traces use the same number of cores). Errors: the device or
  // scene could not be created (the message carries Embree's error code).
  static Expected<std::unique_ptr<EmbreeTracer>> create(EmbreeMode mode, int threads);
  ~EmbreeTracer();
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  // Brings the BVH up to date with `scene`'s current skinned positions (after
  // its prepare_frame): the first call creates one Embree geometry per
  // instance and per static mesh and builds; later calls upload the new
  // positions and rebuild or refit by the mode. The scene's set of instances
  // and static meshes must not change between calls. Returns milliseconds.
  Expected<double> update(const rt::Scene& scene);
  // The same for meshes skinned by the caller: the first call creates one
  // geometry per mesh and builds, later calls upload the new positions and
  // rebuild or refit by the mode. The meshes (their number, triangles and
  // vertex counts) must not change between calls, and a tracer serves
  // either this overload or the scene's, not both.
  Expected<double> update(std::span<const EmbreeMesh> meshes);

  // The nearest hit of one ray through rtcIntersect1 (after an update), in
  // Sinew's ids: the triangle index within its mesh and the mesh's id.
  Hit intersect1(const Ray& ray) const;

  // Renders like rt::Renderer::render with `settings` (its lights and their
  // shadows, hard or soft, its ambient occlusion, diffuse shading) into
  // `color_rgba8` (width x height x 4, may be empty) and, when not empty,
  // the primary hits into `hits` (width x height, Sinew's ids: triangle
  // index within its mesh and the scene's instance id). The shadow and
  // ambient occlusion rays are the renderer's own (rt::trace_light_rays),
  // traced by Embree; area-light samples and ambient occlusion rays go with
  // RTC_INTERSECT_CONTEXT_FLAG_COHERENT when `secondary_coherent`, else
  // INCOHERENT.
  Expected<EmbreeRenderStats> render(const rt::Scene& scene, const rt::PinholeCamera& camera,
                                     const rt::RenderSettings& settings, std::span<std::uint8_t> color_rgba8,
                                     std::span<Hit> hits, JobSystem& jobs, EmbreeWidth width = EmbreeWidth::k16,
                                     bool secondary_coherent = true);

 private:
  struct State;
  explicit EmbreeTracer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace sinew::bench
