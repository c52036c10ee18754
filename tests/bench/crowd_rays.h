// Seeded random gameplay rays into a crowd (`sinew-bench queries`): each
// starts at a random point on a sphere around the crowd's bounds and aims
// at a point the caller picks from a random number (the centre of a random
// triangle of a random character, as posed: a body aimed at), so most of
// them hit some character, as hit scans and lines of sight aimed across a
// crowd do; on the way they pass others.
//
// The generator is the engine's raw 64-bit output turned into floats here
// (not a std distribution, whose algorithm the standard leaves to each
// library), so a seed gives the same rays with every compiler.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "runtime/math/aabb.h"
#include "runtime/math/ray.h"
#include "runtime/math/types.h"

namespace sinew::bench {

class CrowdRays {
 public:
  // `bounds`: the crowd's box (not empty).
  CrowdRays(const Aabb& bounds, std::uint64_t seed) : bounds_(bounds), engine_(seed) {}

  // The next `count` rays; `target(draw)` maps a uniform 64-bit draw to the
  // point a ray aims at. Directions run from the origin to the target (not
  // unit length: t = 1 at the target), t from 0 to infinity.
  template <class Target>
  std::vector<Ray> next(std::size_t count, const Target& target) {
    std::vector<Ray> rays(count);
    const Vec3 centre = 0.5f * (bounds_.lower + bounds_.upper);
    // The sphere's radius: 1.5 times the box's half diagonal, so every
    // origin lies outside the box.
    const float radius = 0.75f * glm::length(bounds_.upper - bounds_.lower);
    for (Ray& ray : rays) {
      ray.origin = centre + radius * on_unit_sphere();
      ray.direction = target(engine_()) - ray.origin;
    }
    return rays;
  }

 private:
  // Uniform in [0, 1): the top 24 bits of one draw.
  float unit() { return static_cast<float>(engine_() >> 40) * 0x1p-24f; }

  // Uniform on the unit sphere (Archimedes: z uniform in [-1, 1]).
  Vec3 on_unit_sphere() {
    const float z = 2.0f * unit() - 1.0f;
    const float phi = 6.28318530718f * unit();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }

  Aabb bounds_;
  std::mt19937_64 engine_;
};

}  // namespace sinew::bench
