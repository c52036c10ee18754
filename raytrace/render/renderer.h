// Renderer: primary rays, shadow rays and diffuse shading over image tiles
// in parallel (paper section 4.1), writing only the outputs (AOVs) the
// caller asks for.
//
// Each tile runs the whole frame for its pixels: nearest hits, surfaces,
// one shadow ray per hit that faces the light, shading and the AOVs. The
// tile's hits and surfaces stay in cache from one step to the next (three
// image-wide passes spent a third of the frame re-reading and re-deriving
// them). The phases ("trace primary", "trace shadow", "shade") are timed per
// tile and the render's wall time is split in their proportion. Tiles are
// fixed squares processed in any order; every pixel's result depends only on
// the scene, so images are identical for any thread count.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/render/packet_traversal.h"
#include "raytrace/render/traversal.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"

namespace sinew {
class JobSystem;
class PhaseTimers;
}  // namespace sinew

namespace sinew::rt {

struct Light {
  enum class Kind : std::uint8_t { kPoint, kDirectional };
  Kind kind = Kind::kPoint;
  Vec3 position{4.0f, 8.0f, 6.0f};   // kPoint
  Vec3 direction{0.4f, 1.0f, 0.6f};  // kDirectional: towards the light (any length)
  Vec3 color{1.0f};                  // linear RGB radiance scale (no distance falloff)
};

// Lights one render shades with, each with its own shadow ray.
inline constexpr std::size_t kMaxLights = 8;

struct RenderSettings {
  TriangleTest triangle_test = TriangleTest::kFast;
  bool shadows = true;
  Light light;
  // When non-empty, these lights (1 to kMaxLights; kept by the caller for
  // the render's duration) replace `light`.
  std::span<const Light> lights;
  Vec3 ambient{0.18f};
  Vec3 background{0.32f, 0.36f, 0.42f};
  Vec3 default_albedo{0.7f};  // meshes without material colors
  int tile_size = 32;
  // Rays traced together: 1 (single rays), 8 (4x2-pixel packets,
  // render/packet_traversal.h), 64, 256 or 512 (8x8-, 16x16- or
  // 32x16-pixel packets culled cell by cell, render/large_packet.h). Shadow rays are packed
  // from the same pixels. The hits agree (large packets may pick another
  // triangle only at an exact tie in t); other values are refused.
  int packet_rays = 256;
  // With packets larger than 8x8 pixels: a packet region whose hits on
  // characters lie on triangles about a pixel across or smaller (two in
  // three neighbouring pixels on different triangles) traces their shadow
  // rays as 8x8-pixel packets, and where some character's triangles look
  // that fine from the camera (characters_look_fine) so do the static
  // meshes' shadow rays. Same results either way; at 855,552 triangles the
  // character's shadow rays take a sixth less time, at 213,888 the ground's
  // a tenth; at 3,342 triangles nothing splits (docs/RAYTRACE.md, "Shadow
  // packets on fine meshes").
  bool split_fine_shadow_packets = true;
};

// Host-owned outputs; an empty span means "not requested" and is neither
// computed nor written. Each non-empty span holds width * height entries
// (colour: 4 bytes per pixel, sRGB-encoded RGBA8), row-major, y = 0 on top,
// unless a row pitch is given for it.
struct FrameBuffers {
  int width = 0;
  int height = 0;
  std::span<std::uint8_t> color_rgba8;
  std::span<float> color_rgba32f;  // linear RGBA
  std::span<float> depth;          // distance along the unit primary ray; +inf on a miss
  std::span<Vec3> normal;          // unit shading normal facing the camera; 0 on a miss
  std::span<std::uint32_t> triangle_id;  // kInvalidId on a miss
  std::span<std::uint32_t> instance_id;  // kInvalidId on a miss

  // Bytes from the start of one row to the next, per output (a host's
  // texture or staging buffer with padded rows); 0: rows packed. A pitch
  // holds at least a row and is a multiple of the element's alignment (4
  // bytes for every output but color_rgba8). With a pitch, the span reaches
  // at least to the end of the last row's last pixel; the padding between
  // rows is never written. Rows on 64-byte lines (span start and pitch
  // multiples of 64) are stored fastest (render/output_staging.h).
  struct RowPitches {
    std::size_t color_rgba8 = 0;
    std::size_t color_rgba32f = 0;
    std::size_t depth = 0;
    std::size_t normal = 0;
    std::size_t triangle_id = 0;
    std::size_t instance_id = 0;
  };
  RowPitches row_pitch;
};

struct RenderStats {
  std::uint64_t primary_rays = 0;
  std::uint64_t primary_hits = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t shadowed = 0;
  TraversalCounters primary;
  TraversalCounters shadow;
  double trace_primary_ms = 0.0;
  double trace_shadow_ms = 0.0;
  double shade_ms = 0.0;
};

class Renderer {
 public:
  // Errors: kInvalidArgument when a buffer's size does not match
  // width x height (or its row pitch), a row pitch is too small or
  // misaligned, the camera's size differs from the buffers', the tile size
  // is below 1, or there are more than kMaxLights lights.
  Expected<RenderStats> render(const Scene& scene, const PinholeCamera& camera,
                               const RenderSettings& settings, const FrameBuffers& buffers,
                               JobSystem& jobs, PhaseTimers* timers = nullptr);
};

// Whether some character instance's triangles come out about a pixel
// across or smaller in `camera`'s image: its world box (the union of its
// bones' boxes this frame), projected, holds at most
// kFineBoxPixelsPerTriangle pixels per triangle. The box holds more pixels
// than the character and half the triangles face away, so that is about a
// pixel or less per visible triangle. An instance whose box reaches behind
// the eye counts as coarse (its triangles near the eye are large). With
// RenderSettings::split_fine_shadow_packets the renderer then traces the
// static meshes' shadow rays, which pass the characters away from their
// ends, in 8x8-pixel packets too (docs/RAYTRACE.md, "Shadow packets on fine
// meshes").
inline constexpr double kFineBoxPixelsPerTriangle = 2.0;
bool characters_look_fine(const Scene& scene, const PinholeCamera& camera);

// The shading inputs at a hit, in world space.
struct SurfacePoint {
  Vec3 position{0.0f};
  Vec3 geometric_normal{0.0f};  // unit
  Vec3 shading_normal{0.0f};    // unit; the geometric normal where no vertex normals exist
  Vec3 albedo{0.0f};
  Vec3 error{0.0f};  // per axis, a bound on the rounding of `position` and of a triangle test started there
};
SurfacePoint surface_at(const Scene& scene, const Hit& hit, const Vec3& default_albedo);

// A directional light's shadow ray origin: `p` pushed off the surface along
// the geometric normal, to the side `toward` points to, by its rounding
// error bound (pbrt-v4's OffsetRayOrigin idea), so neither acne far from
// the origin nor a visible gap at tiny scales.
Vec3 offset_origin(const SurfacePoint& surface, const Vec3& toward);

// A point light's shadow ray: from the light to the surface point pushed
// off toward `toward` (offset_origin), t in [0, 1). Traced from the light,
// a tile's shadow rays share one origin, as its camera rays do
// (docs/RAYTRACE.md, "Shadow rays"). The push covers the point's rounding
// and also a triangle test's along a ray from the light, which grows with
// the light's magnitude and distance: gamma(32) (|light| + 2 |light - p|)
// more per axis, so the ray stops short of the surface it ends on (an
// eighth of it was not enough in tests/raytrace/render_extremes_test.cpp).
Ray shadow_ray_from_light(const SurfacePoint& surface, const Vec3& toward, const Vec3& light);

}  // namespace sinew::rt
