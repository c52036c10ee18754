// The rule for peer benchmarks (docs/BENCHMARKS.md): a configuration whose output fails the
// brute-force check on its first frame is not reported. This compares a
// contender's primary hits with brute force (tests/support/brute_force.h)
// on every `stride`-th pixel of the image.
//
// Tolerances: those of compare_nearest_hits (hit_comparison.h).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"
#include "tests/bench/hit_comparison.h"
#include "tests/support/brute_force.h"

namespace sinew::bench {

struct GateResult {
  std::uint64_t checked = 0;     // sampled pixels
  std::uint64_t mismatched = 0;  // beyond tolerance
  std::uint64_t grazes = 0;      // accepted edge grazes
  bool passed() const { return mismatched == 0; }
};

// The reference: brute-force nearest hits of the sampled pixels.
class BruteForceGate {
 public:
  BruteForceGate(const rt::Scene& scene, const rt::PinholeCamera& camera, int stride)
      : camera_(camera), stride_(std::max(1, stride)), soup_(testing_support::world_triangles(scene)) {
    for (std::uint32_t i = 0; i < soup_.size(); ++i) index_[key(soup_[i].instance_id, soup_[i].triangle_id)] = i;
    const testing_support::ScreenBinner binner(soup_, camera);
    const std::size_t pixels = static_cast<std::size_t>(camera.width()) * static_cast<std::size_t>(camera.height());
    for (std::size_t p = 0; p < pixels; p += static_cast<std::size_t>(stride_)) {
      const int x = static_cast<int>(p % static_cast<std::size_t>(camera.width()));
      const int y = static_cast<int>(p / static_cast<std::size_t>(camera.width()));
      reference_.push_back(binner.nearest(soup_, camera.ray(x, y), x, y, rt::TriangleTest::kWatertight));
    }
  }

  // `hits`: the contender's primary hits, width x height, Sinew's ids.
  GateResult check(std::span<const Hit> hits) const {
    GateResult r;
    const int w = camera_.width();
    std::size_t sample = 0;
    for (std::size_t p = 0; p < hits.size() && sample < reference_.size(); p += static_cast<std::size_t>(stride_)) {
      const Ray ray = camera_.ray(static_cast<int>(p % static_cast<std::size_t>(w)),
                                  static_cast<int>(p / static_cast<std::size_t>(w)));
      ++r.checked;
      const auto corners_of = [this](std::uint32_t instance, std::uint32_t triangle) {
        return this->corners_of(instance, triangle);
      };
      switch (compare_nearest_hits(hits[p], reference_[sample++], ray, corners_of)) {
        case HitVerdict::kSame: break;
        case HitVerdict::kGraze: ++r.grazes; break;
        case HitVerdict::kDifferent: ++r.mismatched; break;
      }
    }
    return r;
  }

 private:
  static std::uint64_t key(std::uint32_t instance, std::uint32_t triangle) {
    return (static_cast<std::uint64_t>(instance) << 32) | triangle;
  }

  std::optional<std::array<Vec3, 3>> corners_of(std::uint32_t instance, std::uint32_t triangle) const {
    const auto it = index_.find(key(instance, triangle));
    if (it == index_.end()) return std::nullopt;
    const testing_support::SoupTriangle& tri = soup_[it->second];
    return std::array<Vec3, 3>{tri.p0, tri.p1, tri.p2};
  }

  rt::PinholeCamera camera_;
  int stride_;
  std::vector<testing_support::SoupTriangle> soup_;
  std::unordered_map<std::uint64_t, std::uint32_t> index_;
  std::vector<Hit> reference_;
};

// The renderer's primary hits, for the gate: untimed renders of the id and
// depth outputs (depth = t: camera rays are unit length), into buffers kept
// from one render to the next (the trade benchmark renders thousands).
class PrimaryHitRenderer {
 public:
  PrimaryHitRenderer(int width, int height)
      : width_(width),
        height_(height),
        triangle_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        instance_(triangle_.size()),
        depth_(triangle_.size()),
        hits_(triangle_.size()) {}

  // `camera` must be width x height. The span lives until the next render.
  Expected<std::span<const Hit>> render(const rt::Scene& scene, const rt::PinholeCamera& camera,
                                        const rt::RenderSettings& settings, JobSystem& jobs) {
    rt::FrameBuffers ids;
    ids.width = width_;
    ids.height = height_;
    ids.triangle_id = triangle_;
    ids.instance_id = instance_;
    ids.depth = depth_;
    const auto rendered = renderer_.render(scene, camera, settings, ids, jobs);
    if (!rendered.ok()) return rendered.status();
    for (std::size_t i = 0; i < hits_.size(); ++i) {
      hits_[i] = triangle_[i] != kInvalidId ? Hit{depth_[i], 0.0f, 0.0f, triangle_[i], instance_[i]} : Hit{};
    }
    return std::span<const Hit>(hits_);
  }

 private:
  int width_, height_;
  std::vector<std::uint32_t> triangle_, instance_;
  std::vector<float> depth_;
  std::vector<Hit> hits_;
  rt::Renderer renderer_;
};

// One render's primary hits, as a vector.
inline Expected<std::vector<Hit>> render_primary_hits(const rt::Scene& scene, const rt::PinholeCamera& camera,
                                                      const rt::RenderSettings& settings, JobSystem& jobs) {
  PrimaryHitRenderer renderer(camera.width(), camera.height());
  const auto hits = renderer.render(scene, camera, settings, jobs);
  if (!hits.ok()) return hits.status();
  return std::vector<Hit>(hits->begin(), hits->end());
}

}  // namespace sinew::bench
