// The demo arena: a checkered ground plane (y = 0, Y up), box obstacles and
// one point light. Until the static kd-tree arrives with the ray tracer the
// obstacles are few enough to test directly; the renderer's structure
// (primary pass, shadow pass, shade pass over tiles) is the one the skinned
// characters will plug into.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "runtime/jobs/job_system.h"
#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::demo {

struct Camera {
  Vec3 eye{0, 2, 8};
  Vec3 target{0, 1, 0};
  Vec3 up{0, 1, 0};
  float fovy_degrees = 50.0f;
};

struct Arena {
  std::vector<Aabb> obstacles;
  std::vector<Vec3> obstacle_colors;
  Vec3 light_position{6, 10, 4};
  float ground_half_size = 40.0f;

  static Arena generate(std::uint32_t seed, int obstacle_count);
};

// Per-pixel buffers of one frame, kept between frames to avoid allocation.
struct FrameBuffers {
  int width = 0;
  int height = 0;
  std::vector<float> t;            // primary hit distance, +inf on a miss
  std::vector<std::int32_t> what;  // -1 miss, 0 ground, 1 + i obstacle i
  std::vector<Vec3> normal;
  std::vector<Vec3> position;      // primary hit point
  std::vector<std::uint8_t> lit;   // 1 when the light is visible
  std::vector<std::uint8_t> rgba;

  void resize(int w, int h);
};

// Renders one frame; records "trace primary", "trace shadow" and "shade".
void render_arena(const Arena& arena, const Camera& camera, JobSystem& jobs, FrameBuffers& fb,
                  PhaseTimers& timers);

}  // namespace sinew::demo
