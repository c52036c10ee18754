// One character walking through a clip, timed frame by frame (prepare_frame
// + render, shadows from a point light), with the traversal counters summed
// and the first frame checked against brute force: what the trade and the
// structures benchmarks measure of each bake.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "character/framing.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/brute_force_gate.h"

namespace sinew::bench {

struct WalkRequest {
  int frames = 10;  // at 30 Hz from the clip's start
  int width = 1024;
  int height = 1024;
  rt::FrameOptions frame_options;
  rt::TriangleTest test = rt::TriangleTest::kFast;
  int gate_stride = 7;  // every Nth pixel of the first frame against brute force
};

// What walks of the same model share: the camera and light framed on the
// first frame, and that frame's brute-force reference (the skinned
// triangles do not depend on the bake, so one reference serves every bake).
struct WalkFraming {
  std::optional<rt::PinholeCamera> camera;
  Vec3 light{0.0f};
  std::unique_ptr<BruteForceGate> gate;
};

// The median of one phase of prepare_frame over the frames timed (0 when
// it never ran).
inline double phase_median(const PhaseTimers& timers, std::string_view phase) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == phase) return s.median_ms;
  }
  return 0.0;
}

struct WalkMeasure {
  std::vector<double> frame_ms;     // prepare_frame + render, per frame
  PhaseTimers timers;               // prepare_frame's phases, every frame
  rt::TraversalCounters primary;    // summed over the frames
  rt::TraversalCounters shadow;
  double cluster_bones = 0.0;       // mean bones on a pose-space cluster's tree a frame
  double cluster_misses = 0.0;      // mean bones a frame whose cluster a vertex left
  GateResult gate;
  std::size_t frame_bytes = 0;      // what the instance's frame holds after the last frame

  double median_frame_ms() const { return median_of(frame_ms); }
  double phase_ms(std::string_view phase) const { return phase_median(timers, phase); }
};

// The memory an instance's frame holds: skinned vertices, bone frames and
// boxes, cluster choices, escaped triangles, leaf boxes.
inline std::size_t instance_frame_bytes(const rt::InstanceFrame& f) {
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(f.skinning) + bytes(f.bone_from_world) + bytes(f.bone_usable) + bytes(f.tolerance) +
         bytes(f.bone_carry) + bytes(f.bone_world_boxes) + bytes(f.positions) + bytes(f.normals) +
         bytes(f.bone_cluster) + bytes(f.bone_check_boxes) + bytes(f.escaped_triangles) +
         f.leaf_boxes.bytes();
}

inline Expected<WalkMeasure> measure_walk(const character::Model& model, const rt::FuzzyCharacterView& fuzzy,
                                          const anim::Clip& clip, const WalkRequest& request, JobSystem& jobs,
                                          WalkFraming& framing) {
  constexpr double kFramesPerSecond = 30.0;
  BenchStage stage;
  SINEW_RETURN_IF_ERROR(stage_instances(model, fuzzy, 1, stage));
  rt::RenderSettings settings;
  settings.triangle_test = request.test;
  settings.shadows = true;
  settings.light.kind = rt::Light::Kind::kPoint;
  std::vector<std::uint8_t> color(4 * static_cast<std::size_t>(request.width) *
                                  static_cast<std::size_t>(request.height));
  rt::FrameBuffers buffers;
  buffers.width = request.width;
  buffers.height = request.height;
  buffers.color_rgba8 = color;
  rt::Renderer renderer;
  PrimaryHitRenderer hits(request.width, request.height);

  WalkMeasure result;
  for (int f = 0; f < request.frames; ++f) {
    SINEW_RETURN_IF_ERROR(pose_instances(model, clip, f / kFramesPerSecond, stage));
    const std::chrono::steady_clock::time_point prepare_start = std::chrono::steady_clock::now();
    SINEW_ASSIGN_OR_RETURN(const rt::FrameStats frame_stats,
                           stage.scene.prepare_frame(request.frame_options, jobs, &result.timers));
    const double prepare_ms = ms_since(prepare_start);
    result.cluster_bones += static_cast<double>(frame_stats.cluster_bones) / request.frames;
    result.cluster_misses += static_cast<double>(frame_stats.cluster_misses) / request.frames;
    if (!framing.camera) {
      const Aabb posed = character::posed_bounds(stage.scene);
      framing.light = character::default_light(posed, stage.up);
      SINEW_ASSIGN_OR_RETURN(framing.camera, rt::PinholeCamera::create(
                                                 character::default_camera(posed, stage.up, request.width,
                                                                           request.height),
                                                 request.width, request.height));
    }
    settings.light.position = framing.light;
    const std::chrono::steady_clock::time_point render_start = std::chrono::steady_clock::now();
    SINEW_ASSIGN_OR_RETURN(const rt::RenderStats stats,
                           renderer.render(stage.scene, *framing.camera, settings, buffers, jobs));
    result.frame_ms.push_back(prepare_ms + ms_since(render_start));
    for (auto [sum, add] : {std::pair{&result.primary, &stats.primary}, std::pair{&result.shadow, &stats.shadow}}) {
      *sum += *add;
    }
    if (f == 0) {
      if (!framing.gate) {
        framing.gate = std::make_unique<BruteForceGate>(stage.scene, *framing.camera, request.gate_stride);
      }
      SINEW_ASSIGN_OR_RETURN(const std::span<const Hit> primary,
                             hits.render(stage.scene, *framing.camera, settings, jobs));
      result.gate = framing.gate->check(primary);
    }
  }
  result.frame_bytes = instance_frame_bytes(stage.scene.instances()[0]);
  return result;
}

}  // namespace sinew::bench
