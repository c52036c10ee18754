// sinew::api::RayTracePass: a frame's prepare (rt::Scene::prepare_frame)
// and render (rt::Renderer) on the host's buffers and threads.
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "embed/api_errors.h"
#include "embed/convert.h"
#include "embed/world_impl.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/frame_visibility.h"
#include "raytrace/render/renderer.h"
#include "runtime/jobs/executor.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/stopwatch.h"
#include "sinew/pass.h"

namespace sinew::api {
namespace {

constexpr int kMaxSide = 16384;
constexpr std::uint32_t kAllOutputs = (Output::kColorRgba8 | Output::kColorRgba32f | Output::kDepth |
                                      Output::kNormal | Output::kInstanceId | Output::kTriangleId | Output::kUv |
                                      Output::kBarycentrics | Output::kMaterialId | Output::kShadowMask |
                                      Output::kAmbientOcclusion)
                                         .bits();

struct OutputInfo {
  Output output;
  const char* name;
  std::size_t bytes_per_pixel;
  OutputBuffer PassOutputs::*buffer;
};
constexpr OutputInfo kOutputs[] = {
    {Output::kColorRgba8, "color_rgba8", 4, &PassOutputs::color_rgba8},
    {Output::kColorRgba32f, "color_rgba32f", 16, &PassOutputs::color_rgba32f},
    {Output::kDepth, "depth", 4, &PassOutputs::depth},
    {Output::kNormal, "normal", 12, &PassOutputs::normal},
    {Output::kInstanceId, "instance_id", 4, &PassOutputs::instance_id},
    {Output::kTriangleId, "triangle_id", 4, &PassOutputs::triangle_id},
    {Output::kUv, "uv", 8, &PassOutputs::uv},
    {Output::kBarycentrics, "barycentrics", 8, &PassOutputs::barycentrics},
    {Output::kMaterialId, "material_id", 4, &PassOutputs::material_id},
    {Output::kShadowMask, "shadow_mask", 4, &PassOutputs::shadow_mask},  // per light
    {Output::kAmbientOcclusion, "ambient_occlusion", 4, &PassOutputs::ambient_occlusion},
};
// What the G-buffer mode writes: the masks alone.
constexpr OutputMask kMaskOutputs = Output::kShadowMask | Output::kAmbientOcclusion;

Error bad(const std::string& what) { return Error{ErrorCode::kInvalidArgument, "RayTracePass: " + what}; }

// The elements of a host buffer of `height` rows `pitch` bytes apart (0:
// packed): exactly the bytes the renderer may touch, rounded up to whole
// elements; the renderer checks the pitch itself.
template <class T>
std::size_t host_elements(std::size_t row_pitch, std::size_t channels, int width, int height) {
  const std::size_t row = static_cast<std::size_t>(width) * channels * sizeof(T);
  const std::size_t pitch = row_pitch == 0 ? row : row_pitch;
  const std::size_t bytes = (static_cast<std::size_t>(height) - 1) * pitch + row;
  return row_pitch == 0 ? static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * channels
                        : (bytes + sizeof(T) - 1) / sizeof(T);
}
template <class T>
std::span<T> host_span(const OutputBuffer& buffer, std::size_t channels, int width, int height) {
  return {static_cast<T*>(buffer.data), host_elements<T>(buffer.row_pitch, channels, width, height)};
}
template <class T>
std::span<const T> host_span(const InputBuffer& buffer, int width, int height) {
  return {static_cast<const T*>(buffer.data), host_elements<T>(buffer.row_pitch, 1, width, height)};
}

bool finite(const Float3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Light i of the inputs, checked, as the renderer's.
Result<rt::Light> internal_light(const Light& in, std::size_t i) {
  const std::string name = "inputs.lights[" + std::to_string(i) + "]";
  if (!finite(in.position) || !finite(in.direction) || !finite(in.color)) return bad(name + ": not finite");
  rt::Light light;
  switch (in.kind) {
    case Light::Kind::kPoint: light.kind = rt::Light::Kind::kPoint; break;
    case Light::Kind::kDirectional: light.kind = rt::Light::Kind::kDirectional; break;
    case Light::Kind::kRect: light.kind = rt::Light::Kind::kRect; break;
    default: return bad(name + ".kind = " + std::to_string(static_cast<int>(in.kind)) + ": not a Light::Kind");
  }
  if (!(std::isfinite(in.radius) && in.radius >= 0.0f)) {
    return bad(name + ".radius = " + std::to_string(in.radius) + ": expected finite and >= 0");
  }
  if (!(in.angular_radius >= 0.0f && in.angular_radius < 1.5f)) {
    return bad(name + ".angular_radius = " + std::to_string(in.angular_radius) + ": expected 0 to below 1.5 radians");
  }
  light.position = detail::to_internal(in.position);
  light.direction = detail::to_internal(in.direction);
  light.color = detail::to_internal(in.color);
  light.radius = in.radius;
  light.angular_radius = in.angular_radius;
  light.edge_u = detail::to_internal(in.edge_u);
  light.edge_v = detail::to_internal(in.edge_v);
  if (in.kind == Light::Kind::kRect &&
      !(finite(in.edge_u) && finite(in.edge_v) && glm::length(glm::cross(light.edge_u, light.edge_v)) > 0.0f)) {
    return bad(name + ".edge_u, edge_v: a rectangle light needs two finite edges spanning an area");
  }
  return light;
}

// The sample counts and the ambient occlusion radius.
Status check_sampling(const PassInputs& inputs) {
  if (inputs.shadow_samples < 1 || inputs.shadow_samples > rt::kMaxSamples) {
    return bad("inputs.shadow_samples = " + std::to_string(inputs.shadow_samples) + ": expected 1 to " +
               std::to_string(rt::kMaxSamples));
  }
  if (inputs.ao_rays < 0 || inputs.ao_rays > rt::kMaxSamples) {
    return bad("inputs.ao_rays = " + std::to_string(inputs.ao_rays) + ": expected 0 to " +
               std::to_string(rt::kMaxSamples));
  }
  if (inputs.ao_rays > 0 && !(std::isfinite(inputs.ao_radius) && inputs.ao_radius > 0.0f)) {
    return bad("inputs.ao_radius = " + std::to_string(inputs.ao_radius) + ": expected finite and above 0");
  }
  return Status();
}

// The G-buffer's buffers and offset as the renderer's HostSurfaces; the
// pitches are checked here, where the inputs' own names are known.
Result<rt::HostSurfaces> host_surfaces(const GBufferInputs& gbuffer, int width, int height) {
  if (gbuffer.normal.data == nullptr) return bad("inputs.gbuffer.normal.data: null, but gbuffer.position is set");
  const std::size_t row = static_cast<std::size_t>(width) * 3 * sizeof(float);
  for (const auto& [buffer, name] : {std::pair{&gbuffer.position, "position"}, std::pair{&gbuffer.normal, "normal"}}) {
    const std::size_t pitch = buffer->row_pitch;
    if (pitch != 0 && (pitch < row || pitch % 4 != 0)) {
      return bad(std::string("inputs.gbuffer.") + name + ".row_pitch = " + std::to_string(pitch) +
                 ": expected 0 or a multiple of 4 bytes holding a row of " + std::to_string(row));
    }
  }
  if (!std::isfinite(gbuffer.normal_offset)) {
    return bad("inputs.gbuffer.normal_offset = " + std::to_string(gbuffer.normal_offset) + ": expected finite");
  }
  rt::HostSurfaces surfaces;
  surfaces.width = width;
  surfaces.height = height;
  surfaces.position = host_span<Vec3>(gbuffer.position, width, height);
  surfaces.normal = host_span<Vec3>(gbuffer.normal, width, height);
  surfaces.row_pitch.position = gbuffer.position.row_pitch;
  surfaces.row_pitch.normal = gbuffer.normal.row_pitch;
  surfaces.normal_offset = gbuffer.normal_offset < 0.0f ? rt::kAutomaticNormalOffset : gbuffer.normal_offset;
  return surfaces;
}

// The host's scheduler as an Executor: each batch goes through run_batch.
std::unique_ptr<Executor> scheduler_executor(const TaskScheduler& scheduler) {
  return make_callback_executor(
      scheduler.concurrency,
      [scheduler](std::size_t count, const std::function<void(std::size_t)>& task) {
        const TaskFunction trampoline = [](void* context, std::uint32_t index) {
          (*static_cast<const std::function<void(std::size_t)>*>(context))(index);
        };
        // Batches beyond 2^32 tasks (never in practice) go in slices.
        constexpr std::size_t kMaxBatch = std::numeric_limits<std::uint32_t>::max();
        for (std::size_t first = 0; first < count; first += kMaxBatch) {
          const std::size_t n = std::min(kMaxBatch, count - first);
          if (first == 0) {
            scheduler.run_batch(scheduler.user, static_cast<std::uint32_t>(n), trampoline,
                                const_cast<std::function<void(std::size_t)>*>(&task));
          } else {
            const std::function<void(std::size_t)> shifted = [&](std::size_t i) { task(first + i); };
            scheduler.run_batch(scheduler.user, static_cast<std::uint32_t>(n), trampoline,
                                const_cast<std::function<void(std::size_t)>*>(&shifted));
          }
        }
      });
}


}  // namespace

struct RayTracePass::Impl {
  PassDesc desc;
  std::vector<ResourceDecl> resources;
  std::unique_ptr<JobSystem> own_jobs;  // the default TBB executor, made on first use
  rt::Renderer renderer;
};

RayTracePass::RayTracePass(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
RayTracePass::~RayTracePass() = default;
RayTracePass::RayTracePass(RayTracePass&&) noexcept = default;
RayTracePass& RayTracePass::operator=(RayTracePass&&) noexcept = default;

Result<RayTracePass> RayTracePass::create(const PassDesc& desc) noexcept {
  return detail::guarded("RayTracePass::create", [&]() -> Result<RayTracePass> {
    const std::string size = std::to_string(desc.width) + "x" + std::to_string(desc.height);
    if (desc.width < 1 || desc.height < 1 || desc.width > kMaxSide || desc.height > kMaxSide) {
      return bad("desc.width x height = " + size + ": expected 1 to " + std::to_string(kMaxSide) + " a side");
    }
    if (desc.outputs.empty() || (desc.outputs.bits() & ~kAllOutputs) != 0) {
      return bad("desc.outputs = " + std::to_string(desc.outputs.bits()) + ": expected a non-empty set of Output bits");
    }
    if (desc.threads < 0) return bad("desc.threads = " + std::to_string(desc.threads) + ": expected >= 0");
    auto impl = std::make_unique<Impl>();
    impl->desc = desc;
    impl->resources = {
        {"bone_matrices", ResourceDecl::Access::kRead, false, 0},
        {"camera", ResourceDecl::Access::kRead, false, 0},
        {"lights", ResourceDecl::Access::kRead, true, 0},
        {"static_geometry", ResourceDecl::Access::kRead, true, 0},
        {"gbuffer", ResourceDecl::Access::kRead, true, 0},
    };
    for (const OutputInfo& o : kOutputs) {
      if (desc.outputs.has(o.output)) {
        impl->resources.push_back({o.name, ResourceDecl::Access::kWrite, false, o.bytes_per_pixel});
      }
    }
    return RayTracePass(std::move(impl));
  });
}

const PassDesc& RayTracePass::desc() const noexcept { return impl_->desc; }

std::span<const ResourceDecl> RayTracePass::resources() const noexcept { return impl_->resources; }

Result<PassStats> RayTracePass::execute(World& world, const PassInputs& inputs, const PassOutputs& outputs,
                                        const TaskScheduler* scheduler) noexcept {
  return detail::guarded("RayTracePass::execute", [&]() -> Result<PassStats> {
    const PassDesc& desc = impl_->desc;
    const int w = desc.width;
    const int h = desc.height;

    // The G-buffer mode writes the masks alone.
    const bool gbuffer = inputs.gbuffer.active();
    if (gbuffer) {
      for (const OutputInfo& o : kOutputs) {
        if (desc.outputs.has(o.output) && !kMaskOutputs.has(o.output)) {
          return bad(std::string("desc.outputs asks for ") + o.name +
                     ", but the G-buffer mode (inputs.gbuffer.position set) writes only shadow_mask and "
                     "ambient_occlusion");
        }
      }
    }
    if (desc.outputs.has(Output::kShadowMask) && inputs.lights.empty()) {
      return bad("outputs.shadow_mask: asked for, but inputs.lights is empty (one channel per light)");
    }
    // Outputs: every requested one needs a buffer; the others are ignored.
    for (const OutputInfo& o : kOutputs) {
      if (desc.outputs.has(o.output) && (outputs.*(o.buffer)).data == nullptr) {
        return bad(std::string("outputs.") + o.name + ".data: null, but the pass's desc.outputs asks for it");
      }
    }
    const auto wanted = [&](Output o) { return desc.outputs.has(o); };
    rt::FrameBuffers buffers;
    buffers.width = w;
    buffers.height = h;
    // Each requested output's span over the host's buffer, and its pitch.
    const auto bind = [&]<class T>(Output o, const OutputBuffer& buffer, std::size_t channels, std::span<T>& span,
                                   std::size_t& pitch) {
      if (!wanted(o)) return;
      span = host_span<T>(buffer, channels, w, h);
      pitch = buffer.row_pitch;
    };
    rt::FrameBuffers::RowPitches& pitch = buffers.row_pitch;
    bind(Output::kColorRgba8, outputs.color_rgba8, 4, buffers.color_rgba8, pitch.color_rgba8);
    bind(Output::kColorRgba32f, outputs.color_rgba32f, 4, buffers.color_rgba32f, pitch.color_rgba32f);
    bind(Output::kDepth, outputs.depth, 1, buffers.depth, pitch.depth);
    bind(Output::kNormal, outputs.normal, 1, buffers.normal, pitch.normal);
    bind(Output::kInstanceId, outputs.instance_id, 1, buffers.instance_id, pitch.instance_id);
    bind(Output::kTriangleId, outputs.triangle_id, 1, buffers.triangle_id, pitch.triangle_id);
    bind(Output::kUv, outputs.uv, 1, buffers.uv, pitch.uv);
    bind(Output::kBarycentrics, outputs.barycentrics, 1, buffers.barycentric, pitch.barycentric);
    bind(Output::kMaterialId, outputs.material_id, 1, buffers.material_id, pitch.material_id);
    bind(Output::kShadowMask, outputs.shadow_mask, inputs.lights.size(), buffers.shadow, pitch.shadow);
    bind(Output::kAmbientOcclusion, outputs.ambient_occlusion, 1, buffers.ambient_occlusion,
         pitch.ambient_occlusion);

    // Inputs: the camera, or the host's surfaces in its place.
    std::optional<rt::PinholeCamera> camera;
    rt::HostSurfaces surfaces;
    if (gbuffer) {
      auto host = host_surfaces(inputs.gbuffer, w, h);
      if (!host.ok()) return host.error();
      surfaces = *host;
    } else {
      const rt::CameraDesc camera_desc{detail::to_internal(inputs.camera.eye),
                                       detail::to_internal(inputs.camera.target),
                                       detail::to_internal(inputs.camera.up), inputs.camera.fovy_degrees};
      auto made = rt::PinholeCamera::create(camera_desc, w, h);
      if (!made.ok()) return bad("inputs.camera: " + made.status().message());
      camera = *made;
    }
    if (const Status sampling = check_sampling(inputs); !sampling.ok()) return sampling.error();
    if (inputs.lights.size() > kMaxLights) {
      return bad("inputs.lights: " + std::to_string(inputs.lights.size()) + " lights, at most " +
                 std::to_string(kMaxLights));
    }
    rt::RenderSettings settings;
    settings.shadows = desc.shadows;
    settings.triangle_test =
        desc.triangle_test == TriangleTest::kWatertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast;
    settings.ambient = detail::to_internal(inputs.ambient);
    settings.background = detail::to_internal(inputs.background);
    settings.camera_mask = inputs.camera_ray_mask;
    settings.shadow_mask = inputs.shadow_ray_mask;
    settings.shadow_samples = inputs.shadow_samples;
    settings.ao_rays = inputs.ao_rays;
    settings.ao_radius = inputs.ao_radius;
    settings.sample_seed = inputs.sample_seed;
    std::vector<rt::Light> lights;
    for (std::size_t i = 0; i < inputs.lights.size(); ++i) {
      auto light = internal_light(inputs.lights[i], i);
      if (!light.ok()) return light.error();
      lights.push_back(*light);
    }
    if (lights.empty()) {
      settings.light.color = Vec3(0.0f);  // ambient only: nothing to cast shadows for
      settings.shadows = false;
    } else {
      settings.lights = lights;
    }

    // Threads: the host's scheduler, or the pass's own TBB arena.
    std::unique_ptr<JobSystem> host_jobs;
    if (scheduler != nullptr) {
      if (scheduler->run_batch == nullptr || scheduler->concurrency < 1) {
        return bad("scheduler: run_batch must be set and concurrency >= 1 (it is " +
                   std::to_string(scheduler->concurrency) + ")");
      }
      host_jobs = std::make_unique<JobSystem>(scheduler_executor(*scheduler));
    } else if (!impl_->own_jobs) {
      impl_->own_jobs = std::make_unique<JobSystem>(desc.threads);
    }
    JobSystem& jobs = host_jobs ? *host_jobs : *impl_->own_jobs;

    // The frame: prepare, then trace and shade. Only colour needs normals.
    rt::FrameOptions frame;
    frame.bone_boxes = desc.exact_bone_boxes ? rt::BoneBoxMode::kExact : rt::BoneBoxMode::kCheap;
    frame.fallback = desc.fallback;
    frame.normals = wanted(Output::kColorRgba8) || wanted(Output::kColorRgba32f) || wanted(Output::kNormal);
    // Skin only what the camera's rays can reach; the host's surfaces may
    // be anywhere, so without a camera every instance is prepared.
    if (camera) frame.visibility = rt::frame_visibility(*camera, settings);
    rt::Scene& scene = world.impl().scene;
    const auto start = std::chrono::steady_clock::now();
    World::Impl& state = world.impl();
    state.prepared_changes = 0;  // half-prepared until it succeeds
    const auto prepared = scene.prepare_frame(frame, jobs);
    if (!prepared.ok()) return detail::to_api_error(prepared.status());
    state.prepared_changes = state.changes;
    // Queries need every instance: a frame that culled some is prepared again.
    state.prepared_exact = desc.fallback && prepared->culled_instances == 0;
    PassStats stats;
    stats.prepare_ms = ms_since(start);
    stats.escaped_triangles = prepared->escaped_triangles;
    stats.fallback_ms = prepared->fallback_ms;
    stats.skinned_instances = prepared->skinned_instances;
    stats.culled_instances = prepared->culled_instances;
    const auto rendered = camera ? impl_->renderer.render(scene, *camera, settings, buffers, jobs)
                                 : impl_->renderer.render_visibility(scene, surfaces, settings, buffers, jobs);
    if (!rendered.ok()) return bad(rendered.status().message());
    stats.trace_ms = rendered->trace_primary_ms + rendered->trace_shadow_ms + rendered->trace_ao_ms;
    stats.shade_ms = rendered->shade_ms;
    stats.primary_rays = rendered->primary_rays;
    stats.shadow_rays = rendered->shadow_rays;
    stats.ao_rays = rendered->ao_rays;
    return stats;
  });
}

}  // namespace sinew::api
