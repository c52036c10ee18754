// The ray-trace pass: what a host's render graph calls once per frame. It
// declares its inputs (per-instance bone matrices, camera, lights, optional
// static geometry) and outputs (the AOVs the host asked for), and writes
// only those outputs, into host-owned buffers with host-chosen row pitches.
//
//   auto pass = RayTracePass::create({.width = 1024, .height = 1024,
//                                     .outputs = Output::kColorRgba8 | Output::kDepth});
//   PassOutputs out;
//   out.color_rgba8 = {color.data(), 1024 * 4};
//   out.depth = {depth.data(), 1024 * sizeof(float)};
//   pass->execute(world, inputs, out);
//
// execute() prepares the frame (skinning, the escape check, bone boxes, the
// fallback for escaped triangles, the top-level tree), then traces and
// shades the image in tiles; or, given the host's G-buffer (GBufferInputs),
// traces shadow and ambient occlusion rays from the host's own surfaces. Images are identical for any thread count or
// scheduler.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "sinew/export.h"
#include "sinew/math.h"
#include "sinew/result.h"
#include "sinew/tasks.h"
#include "sinew/view.h"
#include "sinew/world.h"

namespace sinew::api {

// The outputs (AOVs). Formats, one pixel each, rows top to bottom:
enum class Output : std::uint32_t {
  kColorRgba8 = 1u << 0,    // 4 x uint8: sRGB-encoded colour, alpha 255
  kColorRgba32f = 1u << 1,  // 4 x float: linear colour, alpha 1
  kDepth = 1u << 2,         // float: distance from the eye along the unit view ray; +inf on a miss
  kNormal = 1u << 3,        // 3 x float: unit shading normal facing the camera; 0 on a miss
  kInstanceId = 1u << 4,    // uint32: World's InstanceId; kNoHit on a miss
  kTriangleId = 1u << 5,    // uint32: the character's (or static mesh's) triangle; kNoHit on a miss
  kUv = 1u << 6,            // 2 x float: texture coordinates (the corners' uvs blended); 0 without uvs or on a miss
  kBarycentrics = 1u << 7,  // 2 x float: u, v, the hit's weights of the triangle's corners 1 and 2; 0 on a miss
  kMaterialId = 1u << 8,    // uint32: the triangle's material, as the pack numbers them; kNoHit without one or on a miss
  // Visibility masks, 1 where nothing blocks and where there is no surface:
  // float per light, interleaved (inputs.lights.size() floats a pixel, in
  // the lights' order): 0 or 1 for a hard light, for an area light the
  // fraction of its samples that reach the surface; 0 where the surface
  // faces away from the light. 1 for every light with desc.shadows off.
  kShadowMask = 1u << 9,
  // float: the fraction of the ambient occlusion rays that escape
  // (PassInputs::ao_rays; 1 without them).
  kAmbientOcclusion = 1u << 10,
};
// A set of outputs: `Output::kColorRgba8 | Output::kDepth`, or one Output.
class OutputMask {
 public:
  constexpr OutputMask() = default;
  constexpr OutputMask(Output o) : bits_(static_cast<std::uint32_t>(o)) {}  // NOLINT: implicit by design
  constexpr explicit OutputMask(std::uint32_t bits) : bits_(bits) {}

  constexpr std::uint32_t bits() const { return bits_; }
  constexpr bool empty() const { return bits_ == 0; }
  constexpr bool has(Output o) const { return (bits_ & static_cast<std::uint32_t>(o)) != 0; }
  friend constexpr OutputMask operator|(OutputMask a, OutputMask b) { return OutputMask(a.bits_ | b.bits_); }
  friend constexpr bool operator==(OutputMask a, OutputMask b) { return a.bits_ == b.bits_; }

 private:
  std::uint32_t bits_ = 0;
};
constexpr OutputMask operator|(Output a, Output b) { return OutputMask(a) | OutputMask(b); }

// TriangleTest: sinew/world.h (the World's ray queries take one too).

struct PassDesc {
  int width = 1024;
  int height = 1024;
  OutputMask outputs = Output::kColorRgba8;
  bool shadows = true;  // shadow rays per hit and light (for the colour and the shadow mask)
  TriangleTest triangle_test = TriangleTest::kFast;
  // Exact per-bone world boxes (a pass over the bone's triangles) or the
  // cheap fuzzy root box carried by the bone matrix: looser, faster to make.
  bool exact_bone_boxes = true;
  // Trace triangles that left their fuzzy boxes (poses outside the baked
  // pose space) through a per-frame tree, so the image stays exact. Off:
  // escapes are still counted (PassStats) and may show as holes.
  bool fallback = true;
  // Threads of the pass's own TBB arena, made the first time execute() runs
  // without a TaskScheduler (never, for a host that always passes one);
  // 0: all cores.
  int threads = 0;
};

// Camera and Light: sinew/view.h (Character::framing suggests both).
inline constexpr std::size_t kMaxLights = 8;

// A host buffer the pass reads: `height` rows `row_pitch` bytes apart (0:
// packed), a multiple of 4 bytes.
struct InputBuffer {
  const void* data = nullptr;
  std::size_t row_pitch = 0;
};

// The G-buffer mode (hybrid rendering): the host's own rasterised surfaces
// as the origins of the shadow and ambient occlusion rays, in place of the
// pass's camera. The host's surfaces receive; Sinew's characters and static
// meshes (World) occlude; the host's surfaces block nothing (they are not
// in the World). The pass then writes only the masks (Output::kShadowMask,
// kAmbientOcclusion), desc.width x desc.height pixels, one per G-buffer
// pixel.
struct GBufferInputs {
  // 3 x float per pixel: the surface's world position; a non-finite one
  // (the sky, or what the host left empty) has no surface: its masks are 1.
  InputBuffer position;
  // 3 x float per pixel: the surface's unit world normal, on the side the
  // rays leave from (a normal a little off unit, from an 8- or 16-bit
  // encoding, is normalised); zero or non-finite: no surface.
  InputBuffer normal;
  // How far each ray's origin is pushed off the surface along its normal
  // (world units), so that a host surface that coincides with Sinew's own
  // (the host also rasterises the characters) does not shadow itself
  // through the rounding of its reconstructed position. Negative: automatic,
  // a ten-thousandth of the diagonal of the World's bounds this frame.
  float normal_offset = -1.0f;

  bool active() const { return position.data != nullptr; }
};

struct PassInputs {
  Camera camera;  // unused in the G-buffer mode
  std::span<const Light> lights;  // 0 to kMaxLights; none: ambient only
  Float3 ambient{0.18f, 0.18f, 0.18f};
  Float3 background{0.32f, 0.36f, 0.42f};  // linear RGB of a miss
  // Camera rays see, and shadow rays are blocked by, only the instances and
  // static meshes whose mask (InstanceDesc::mask, World::set_mask) shares a
  // bit with these: a first-person body that shadows the floor but is not
  // drawn, a ground that receives shadows but casts none.
  std::uint32_t camera_ray_mask = 0xFFFFFFFFu;
  std::uint32_t shadow_ray_mask = 0xFFFFFFFFu;
  // Soft shadows and ambient occlusion (docs/EMBEDDING.md): rays per hit towards
  // each area light (Light::radius, angular_radius, kRect), 1 to 256; ambient
  // occlusion rays per hit (0: off, up to 256), cosine distributed about the
  // surface, each ao_radius long (world units), which scale the ambient
  // term by the fraction that escape. The sample pattern is a fixed
  // function of sample_seed, the pixel and the sample: the same image for
  // any thread count.
  int shadow_samples = 4;
  int ao_rays = 0;
  float ao_radius = 1.0f;
  std::uint32_t sample_seed = 0;
  // Set gbuffer.position (and normal) to trace from the host's surfaces
  // instead of the camera (GBufferInputs).
  GBufferInputs gbuffer;
};

// A host buffer: `data` holds `height` rows, `row_pitch` bytes apart (0:
// packed, width x pixel size). The pitch must hold a row and be a multiple
// of 4 bytes for every output but colour RGBA8. Bytes between rows are never
// written. Rows on 64-byte lines (data and pitch multiples of 64) are
// stored fastest, as whole lines.
struct OutputBuffer {
  void* data = nullptr;
  std::size_t row_pitch = 0;
};

// One buffer per requested output; the others are ignored and untouched.
struct PassOutputs {
  OutputBuffer color_rgba8;
  OutputBuffer color_rgba32f;
  OutputBuffer depth;
  OutputBuffer normal;
  OutputBuffer instance_id;
  OutputBuffer triangle_id;
  OutputBuffer uv;
  OutputBuffer barycentrics;
  OutputBuffer material_id;
  OutputBuffer shadow_mask;
  OutputBuffer ambient_occlusion;
};

// One declared resource, for a render graph's bookkeeping.
struct ResourceDecl {
  enum class Access : std::uint8_t { kRead, kWrite };
  const char* name;  // "bone_matrices", "camera", "lights", "static_geometry", "gbuffer", "color_rgba8", ...
  Access access;
  bool optional;
  // Outputs: the element size per pixel (the shadow mask's per light);
  // inputs: 0.
  std::size_t bytes_per_pixel;
};

struct PassStats {
  double prepare_ms = 0.0;  // skinning, boxes, fallback, top level
  double trace_ms = 0.0;    // primary, shadow and ambient occlusion rays
  double shade_ms = 0.0;
  std::uint64_t primary_rays = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t ao_rays = 0;
  std::size_t escaped_triangles = 0;  // triangles outside their fuzzy boxes this frame
  // Of prepare_ms: building the per-frame tree over the escaped triangles,
  // what poses outside the baked pose space cost (0 inside it; the rays
  // that enter that tree are in trace_ms). A large share of the frame says
  // the character plays poses it was not baked over: bake them
  // (docs/EDITOR.md, "Why is my character slow?").
  double fallback_ms = 0.0;
  // Instances skinned for the frame, and those left out because none of its
  // camera or shadow rays can reach them (their poses still advance).
  std::size_t skinned_instances = 0;
  std::size_t culled_instances = 0;
};

class SINEW_API RayTracePass {
 public:
  // Errors: kInvalidArgument (size below 1x1 or above 16384 a side, no
  // outputs, unknown output bits, negative threads).
  static Result<RayTracePass> create(const PassDesc& desc) noexcept;
  ~RayTracePass();
  RayTracePass(RayTracePass&&) noexcept;
  RayTracePass& operator=(RayTracePass&&) noexcept;
  RayTracePass(const RayTracePass&) = delete;
  RayTracePass& operator=(const RayTracePass&) = delete;

  const PassDesc& desc() const noexcept;
  // The pass's inputs, then the outputs its desc asked for.
  std::span<const ResourceDecl> resources() const noexcept;

  // Renders `world` into `outputs`; in the G-buffer mode
  // (inputs.gbuffer.active()), traces from the host's surfaces and writes
  // only the masks. With a scheduler, every parallel batch runs through it;
  // otherwise on the pass's TBB arena. Errors: kInvalidArgument naming the
  // input or output (a null buffer for a requested output, a bad pitch, a
  // bad camera, too many lights, a light's bad size, sample counts out of
  // range, a shadow mask without lights, in the G-buffer mode an output
  // other than the masks or a missing normal buffer); nothing is written
  // then.
  Result<PassStats> execute(World& world, const PassInputs& inputs, const PassOutputs& outputs,
                            const TaskScheduler* scheduler = nullptr) noexcept;

  struct Impl;

 private:
  explicit RayTracePass(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew::api
