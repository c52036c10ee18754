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
// shades the image in tiles. Images are identical for any thread count or
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
  bool shadows = true;  // one shadow ray per hit and light (colour outputs only)
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

struct PassInputs {
  Camera camera;
  std::span<const Light> lights;  // 0 to kMaxLights; none: ambient only
  Float3 ambient{0.18f, 0.18f, 0.18f};
  Float3 background{0.32f, 0.36f, 0.42f};  // linear RGB of a miss
  // Camera rays see, and shadow rays are blocked by, only the instances and
  // static meshes whose mask (InstanceDesc::mask, World::set_mask) shares a
  // bit with these: a first-person body that shadows the floor but is not
  // drawn, a ground that receives shadows but casts none.
  std::uint32_t camera_ray_mask = 0xFFFFFFFFu;
  std::uint32_t shadow_ray_mask = 0xFFFFFFFFu;
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
};

// One declared resource, for a render graph's bookkeeping.
struct ResourceDecl {
  enum class Access : std::uint8_t { kRead, kWrite };
  const char* name;  // "bone_matrices", "camera", "lights", "static_geometry", "color_rgba8", ...
  Access access;
  bool optional;
  std::size_t bytes_per_pixel;  // outputs: the element size per pixel; inputs: 0
};

struct PassStats {
  double prepare_ms = 0.0;  // skinning, boxes, fallback, top level
  double trace_ms = 0.0;    // primary and shadow rays
  double shade_ms = 0.0;
  std::uint64_t primary_rays = 0;
  std::uint64_t shadow_rays = 0;
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

  // Renders `world` into `outputs`. With a scheduler, every parallel batch
  // runs through it; otherwise on the pass's TBB arena. Errors:
  // kInvalidArgument naming the input or output (a null buffer for a
  // requested output, a bad pitch, a bad camera, too many lights); nothing
  // is written then.
  Result<PassStats> execute(World& world, const PassInputs& inputs, const PassOutputs& outputs,
                            const TaskScheduler* scheduler = nullptr) noexcept;

  struct Impl;

 private:
  explicit RayTracePass(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew::api
