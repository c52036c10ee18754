// What one render is asked for: the lights, the settings that trade speed
// for accuracy or choose the ray layout, the host's output buffers, and the
// statistics it returns (render/renderer.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/render/sampling/sample_pattern.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/math/types.h"

namespace sinew::rt {

struct Light {
  enum class Kind : std::uint8_t { kPoint, kDirectional, kRect };
  Kind kind = Kind::kPoint;
  Vec3 position{4.0f, 8.0f, 6.0f};   // kPoint, kRect: the centre
  Vec3 direction{0.4f, 1.0f, 0.6f};  // kDirectional: towards the light (any length)
  Vec3 color{1.0f};                  // linear RGB radiance scale (no distance falloff)
  // The light's size; a light of size 0 is hard (one shadow ray per hit).
  // An area light takes RenderSettings::shadow_samples rays per hit to
  // stratified points on it (docs/RAYTRACE.md, "Soft shadows").
  float radius = 0.0f;          // kPoint: a sphere light's radius (scene units)
  float angular_radius = 0.0f;  // kDirectional: the sun's half angle (radians, below pi/2)
  // kRect: the rectangle's two full edges (it spans position +- edge / 2);
  // it lights both of its sides.
  Vec3 edge_u{0.0f}, edge_v{0.0f};

  bool is_area() const {
    switch (kind) {
      case Kind::kPoint: return radius > 0.0f;
      case Kind::kDirectional: return angular_radius > 0.0f;
      case Kind::kRect: return true;
    }
    return false;
  }
};

// Lights one render shades with, each with its own shadow ray.
inline constexpr std::size_t kMaxLights = 8;

// The coarsest and finest grids RenderSettings::sphere_disk_steps takes
// (at 4 a disk may turn 29 degrees off facing its hit, at 2 it would turn
// 55).
inline constexpr int kMinSphereDiskSteps = 4;
inline constexpr int kMaxSphereDiskSteps = 1 << 20;

struct RenderSettings {
  TriangleTest triangle_test = TriangleTest::kFast;
  bool shadows = true;
  // Shadow rays per hit towards each area light (Light::is_area), 1 to
  // kMaxSamples; hard lights take one.
  int shadow_samples = 4;
  // Ambient occlusion: rays per hit (0: off, up to kMaxSamples), cosine
  // distributed about the surface, each ao_radius long (scene units); the
  // ambient term is scaled by the fraction that escape.
  int ao_rays = 0;
  float ao_radius = 1.0f;
  // The stochastic rays' pattern (render/sampling/sample_pattern.h): a
  // function of this seed, the pixel and the sample.
  std::uint32_t sample_seed = 0;
  // A sphere light's samples lie on its disk facing the hit, turned in
  // steps: the disk's axis is the hit's direction snapped to a grid of this
  // many points per unit on the octahedron (docs/RAYTRACE.md, "The rays"),
  // so that neighbouring hits share sample points and trace as packets from
  // one point. The disk is at most about 122 / steps degrees off facing
  // the hit: 7.6 at 16; each doubling halves that and splits packets finer.
  // 0: every hit's own facing disk. 0 or a power of two from
  // kMinSphereDiskSteps to kMaxSphereDiskSteps.
  int sphere_disk_steps = 16;
  // Textured materials sample their texture (docs/RAYTRACE.md, "Textures");
  // off, every material shows its colour alone.
  bool textures = true;
  // Per-instance mask bits (Scene::set_mask): camera rays see, and shadow
  // rays are blocked by, only the objects whose mask shares a bit with
  // these (a first-person body that casts a shadow but is not drawn).
  std::uint32_t camera_mask = 0xFFFFFFFFu;
  std::uint32_t shadow_mask = 0xFFFFFFFFu;
  Light light;
  // When non-empty, these lights (1 to kMaxLights; kept by the caller for
  // the render's duration) replace `light`.
  std::span<const Light> lights;
  Vec3 ambient{0.18f};
  Vec3 background{0.32f, 0.36f, 0.42f};
  Vec3 default_albedo{0.7f};  // meshes without material colors
  int tile_size = 32;
  // Rays traced together: 1 (single rays), 8 (4x2-pixel packets,
  // traverse/packet_traversal.h), 64, 256 or 512 (8x8-, 16x16- or
  // 32x16-pixel packets culled cell by cell, traverse/large_packet.h). Shadow rays are packed
  // from the same pixels. The hits agree (large packets may pick another
  // triangle only at an exact tie in t); other values are refused.
  int packet_rays = 256;
  // With packets larger than 8x8 pixels: a packet region whose hits on
  // characters lie on triangles about a pixel across or smaller (two in
  // three neighbouring pixels on different triangles) traces their shadow
  // rays as 8x8-pixel packets, and where some character's triangles look
  // that fine from the camera (characters_look_fine) so do the static
  // meshes' shadow rays. Same results either way: it pays on finely
  // subdivided characters and changes nothing on coarse ones, where no
  // region splits (docs/RAYTRACE.md, "Shadow packets on fine meshes").
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
  // The hit's texture coordinates (the corners' uvs blended; 0 without
  // uvs), its barycentrics (u, v: the weights of corners 1 and 2) and its
  // triangle's material (kInvalidId without one); 0, 0 and kInvalidId on a
  // miss.
  std::span<Vec2> uv;
  std::span<Vec2> barycentric;
  std::span<std::uint32_t> material_id;
  // Visibility masks, 1 where nothing blocks and on a miss: per pixel, one
  // float per light (the render's lights, in order): 0 or 1 for a hard
  // light, the fraction of its samples that reach the hit for an area
  // light (1 with shadows off); and the fraction of the ambient occlusion
  // rays that escape (1 without them).
  std::span<float> shadow;
  std::span<float> ambient_occlusion;

  // Bytes from the start of one row to the next, per output (a host's
  // texture or staging buffer with padded rows); 0: rows packed. A pitch
  // holds at least a row and is a multiple of the element's alignment (4
  // bytes for every output but color_rgba8). With a pitch, the span reaches
  // at least to the end of the last row's last pixel; the padding between
  // rows is never written. Rows on 64-byte lines (span start and pitch
  // multiples of 64) are stored fastest (render/output/output_staging.h).
  struct RowPitches {
    std::size_t color_rgba8 = 0;
    std::size_t color_rgba32f = 0;
    std::size_t depth = 0;
    std::size_t normal = 0;
    std::size_t triangle_id = 0;
    std::size_t instance_id = 0;
    std::size_t uv = 0;
    std::size_t barycentric = 0;
    std::size_t material_id = 0;
    std::size_t shadow = 0;
    std::size_t ambient_occlusion = 0;
  };
  RowPitches row_pitch;
};

struct RenderStats {
  std::uint64_t primary_rays = 0;
  std::uint64_t primary_hits = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t shadowed = 0;
  std::uint64_t ao_rays = 0;
  std::uint64_t ao_occluded = 0;
  TraversalCounters primary;
  TraversalCounters shadow;  // hard and area lights' shadow rays
  TraversalCounters ao;
  double trace_primary_ms = 0.0;
  double trace_shadow_ms = 0.0;
  double trace_ao_ms = 0.0;
  double shade_ms = 0.0;
};

}  // namespace sinew::rt
