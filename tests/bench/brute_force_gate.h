// The rule for peer benchmarks (docs/BENCHMARKS.md): a configuration whose output fails the
// brute-force check on its first frame is not reported. This compares a
// contender's primary hits with brute force (tests/support/brute_force.h)
// on every `stride`-th pixel of the image.
//
// Tolerances: t relative 1e-4. A different triangle at the same t passes
// when the ray really hits it there (a shared edge or vertex). A hit
// against a miss, or a nearer hit on one side only, passes when the nearer
// triangle is only grazed (its smallest barycentric within 1e-5 of 0 in
// double precision): two float triangle tests may decide such a ray either
// way. Grazes are counted and reported.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"
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
      switch (compare(hits[p], reference_[sample++], ray)) {
        case Verdict::kSame: break;
        case Verdict::kGraze: ++r.grazes; break;
        case Verdict::kDifferent: ++r.mismatched; break;
      }
    }
    return r;
  }

 private:
  enum class Verdict { kSame, kGraze, kDifferent };
  static constexpr double kTolerance = 1e-4;
  static constexpr double kGrazeBarycentric = 1e-5;

  static std::uint64_t key(std::uint32_t instance, std::uint32_t triangle) {
    return (static_cast<std::uint64_t>(instance) << 32) | triangle;
  }

  // The ray against the hit's triangle in double precision: its t and its
  // smallest barycentric (negative: outside). False for an unknown id or a
  // ray parallel to the plane.
  bool exact_hit(const Hit& hit, const Ray& ray, double& t, double& min_bary) const {
    const auto it = index_.find(key(hit.instance_id, hit.triangle_id));
    if (it == index_.end()) return false;
    const testing_support::SoupTriangle& tri = soup_[it->second];
    const auto d = [](const Vec3& v) { return std::array<double, 3>{v.x, v.y, v.z}; };
    const auto sub = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      return std::array<double, 3>{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    };
    const auto cross = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      return std::array<double, 3>{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    const auto dot = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    };
    const auto p0 = d(tri.p0), e1 = sub(d(tri.p1), p0), e2 = sub(d(tri.p2), p0);
    const auto dir = d(ray.direction);
    const auto pv = cross(dir, e2);
    const double det = dot(e1, pv);
    if (det == 0.0) return false;
    const auto tv = sub(d(ray.origin), p0);
    const double u = dot(tv, pv) / det;
    const auto qv = cross(tv, e1);
    const double v = dot(dir, qv) / det;
    t = dot(e2, qv) / det;
    min_bary = std::min({u, v, 1.0 - u - v});
    return true;
  }

  bool grazed(const Hit& hit, const Ray& ray) const {
    double t = 0.0, min_bary = 0.0;
    return exact_hit(hit, ray, t, min_bary) && std::fabs(min_bary) <= kGrazeBarycentric;
  }

  Verdict compare(const Hit& ours, const Hit& ref, const Ray& ray) const {
    if (!ours.valid() && !ref.valid()) return Verdict::kSame;
    if (ours.valid() && ref.valid()) {
      const double tol = kTolerance * std::max(static_cast<double>(std::fabs(ref.t)), 1e-30);
      if (std::fabs(static_cast<double>(ours.t) - static_cast<double>(ref.t)) <= tol) {
        if (ours.triangle_id == ref.triangle_id && ours.instance_id == ref.instance_id) return Verdict::kSame;
        double t = 0.0, min_bary = 0.0;  // another triangle at the same t: does the ray really hit it there?
        const bool real = exact_hit(ours, ray, t, min_bary) && min_bary >= -kGrazeBarycentric &&
                          std::fabs(t - static_cast<double>(ref.t)) <= tol;
        if (real) return Verdict::kSame;
        // The reference's own hit on an edge: the ray passes through the
        // edge, and the triangle across it at the same t is a tie that the
        // float test may settle either way (its barycentrics are those of
        // another triangle, so its distance past the edge is on another
        // scale).
        return grazed(ref, ray) ? Verdict::kGraze : Verdict::kDifferent;
      }
      // Different depths: the nearer one must be a graze the other missed.
      const Hit& nearer = ours.t < ref.t ? ours : ref;
      return grazed(nearer, ray) ? Verdict::kGraze : Verdict::kDifferent;
    }
    return grazed(ours.valid() ? ours : ref, ray) ? Verdict::kGraze : Verdict::kDifferent;
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
