// sinew::api::RayTracePass: a frame's prepare (rt::Scene::prepare_frame)
// and render (rt::Renderer) on the host's buffers and threads.
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
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
                                      Output::kBarycentrics | Output::kMaterialId)
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
};

Error bad(const std::string& what) { return Error{ErrorCode::kInvalidArgument, "RayTracePass: " + what}; }

// A typed span over a host buffer of `height` rows `pitch` bytes apart (0:
// packed), covering exactly the bytes the renderer may touch, rounded up
// to whole elements; the renderer checks the pitch itself.
template <class T>
std::span<T> host_span(const OutputBuffer& buffer, std::size_t channels, int width, int height) {
  const std::size_t row = static_cast<std::size_t>(width) * channels * sizeof(T);
  const std::size_t pitch = buffer.row_pitch == 0 ? row : buffer.row_pitch;
  const std::size_t bytes = (static_cast<std::size_t>(height) - 1) * pitch + row;
  const std::size_t elements = buffer.row_pitch == 0 ? static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * channels
                                                     : (bytes + sizeof(T) - 1) / sizeof(T);
  return {static_cast<T*>(buffer.data), elements};
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

    // Inputs.
    const rt::CameraDesc camera_desc{detail::to_internal(inputs.camera.eye), detail::to_internal(inputs.camera.target),
                                     detail::to_internal(inputs.camera.up), inputs.camera.fovy_degrees};
    const auto camera = rt::PinholeCamera::create(camera_desc, w, h);
    if (!camera.ok()) return bad("inputs.camera: " + camera.status().message());
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
    std::vector<rt::Light> lights;
    for (std::size_t i = 0; i < inputs.lights.size(); ++i) {
      const Light& in = inputs.lights[i];
      rt::Light light;
      light.kind = in.kind == Light::Kind::kDirectional ? rt::Light::Kind::kDirectional : rt::Light::Kind::kPoint;
      light.position = detail::to_internal(in.position);
      light.direction = detail::to_internal(in.direction);
      light.color = detail::to_internal(in.color);
      for (const Vec3& v : {light.position, light.direction, light.color}) {
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
          return bad("inputs.lights[" + std::to_string(i) + "]: not finite");
        }
      }
      lights.push_back(light);
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
    frame.visibility = rt::frame_visibility(*camera, settings);  // skin only what the rays can reach
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
    const auto rendered = impl_->renderer.render(scene, *camera, settings, buffers, jobs);
    if (!rendered.ok()) return bad(rendered.status().message());
    stats.trace_ms = rendered->trace_primary_ms + rendered->trace_shadow_ms;
    stats.shade_ms = rendered->shade_ms;
    stats.primary_rays = rendered->primary_rays;
    stats.shadow_rays = rendered->shadow_rays;
    return stats;
  });
}

}  // namespace sinew::api
