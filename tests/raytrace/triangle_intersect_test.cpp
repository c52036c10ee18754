#include "raytrace/geometry/triangle_intersect.h"

#include "raytrace/geometry/triangle_intersect8.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <vector>

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Deterministic floats from mt19937 (no std::uniform_real_distribution: its
// output differs between standard libraries).
class Random {
 public:
  explicit Random(std::uint32_t seed) : engine_(seed) {}
  // [0, 1) with 24 random bits.
  float unit() { return static_cast<float>(engine_() >> 8) * (1.0f / 16777216.0f); }
  float range(float lo, float hi) { return lo + (hi - lo) * unit(); }
  Vec3 box(float lo, float hi) { return {range(lo, hi), range(lo, hi), range(lo, hi)}; }
  Vec3 unit_vector() {
    for (;;) {
      const Vec3 v = box(-1.0f, 1.0f);
      const float len2 = glm::dot(v, v);
      if (len2 > 0.01f && len2 <= 1.0f) return v / std::sqrt(len2);
    }
  }
  std::uint32_t below(std::uint32_t n) { return engine_() % n; }

 private:
  std::mt19937 engine_;
};

// Both tests behind one call, so every check runs on both.
bool intersect(TriangleTest test, const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2,
               TriangleHit& hit) {
  if (test == TriangleTest::kFast) return intersect_triangle_fast(ray, ray.t_max, p0, p1, p2, hit);
  return intersect_triangle_watertight(prepare_watertight(ray), ray, ray.t_max, p0, p1, p2, hit);
}

const char* name(TriangleTest test) { return test == TriangleTest::kFast ? "fast" : "watertight"; }
constexpr TriangleTest kBothTests[] = {TriangleTest::kFast, TriangleTest::kWatertight};

// The independent reference: Cramer's rule for o + t d = p0 + u e1 + v e2,
// in double from the float inputs.
struct Reference {
  bool solvable = false;
  double t = 0.0, u = 0.0, v = 0.0;
  double sin_angle = 0.0;  // |sin| of the angle between ray and plane
  double shape = 0.0;      // 2 area / longest edge^2: near 0 for slivers
  // How much float rounding of the inputs' size can move t (relatively) and
  // u, v: (distance from the ray origin, or the triangle's size if larger)
  // times the longest edge over (2 area sin(angle)).
  double condition = 0.0;
};

Reference solve_in_double(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const glm::dvec3 o(ray.origin), d(ray.direction), a(p0);
  const glm::dvec3 e1 = glm::dvec3(p1) - a;
  const glm::dvec3 e2 = glm::dvec3(p2) - a;
  const glm::dvec3 normal = glm::cross(e1, e2);
  const double det = -glm::dot(d, normal);
  Reference r;
  if (det == 0.0) return r;
  const glm::dvec3 w = o - a;
  r.solvable = true;
  r.t = glm::dot(w, normal) / det;
  r.u = -glm::dot(d, glm::cross(w, e2)) / det;
  r.v = -glm::dot(d, glm::cross(e1, w)) / det;
  r.sin_angle = std::abs(det) / (glm::length(d) * glm::length(normal));
  const double longest = std::max({glm::length(e1), glm::length(e2), glm::length(e2 - e1)});
  r.shape = glm::length(normal) / (longest * longest);
  const double reach = std::max(glm::length(w), longest);
  r.condition = reach * longest / (glm::length(normal) * r.sin_angle);
  return r;
}

bool reference_hits(const Reference& r, const Ray& ray) {
  return r.solvable && r.u >= 0.0 && r.v >= 0.0 && r.u + r.v <= 1.0 &&
         r.t >= static_cast<double>(ray.t_min) && r.t < static_cast<double>(ray.t_max);
}

// Distance (in barycentric or relative-t units) of the reference from a
// hit/miss boundary; within a tiny margin float and double may disagree.
double boundary_margin(const Reference& r, const Ray& ray) {
  double m = std::min({std::abs(r.u), std::abs(r.v), std::abs(1.0 - r.u - r.v)});
  const double scale = std::max(std::abs(r.t), 1.0);
  m = std::min(m, std::abs(r.t - static_cast<double>(ray.t_min)) / scale);
  if (std::isfinite(ray.t_max)) m = std::min(m, std::abs(r.t - static_cast<double>(ray.t_max)) / scale);
  return m;
}

constexpr double kEdgeMargin = 1e-4;    // skip cases this close to a hit/miss boundary
constexpr double kMaxCondition = 20.0;  // and ill-conditioned ones (grazing rays, slivers)
constexpr double kTolerance = 1e-5;     // t relative, u and v absolute (they lie in [0,1])

bool well_conditioned(const Reference& r, const Ray& ray) {
  return r.solvable && r.condition <= kMaxCondition && boundary_margin(r, ray) >= kEdgeMargin;
}

double relative_error(double actual, double expected) {
  return std::abs(actual - expected) / std::max(std::abs(expected), 1e-30);
}

struct RandomCase {
  Ray ray;
  Vec3 p0, p1, p2;
};

// Triangles in [-1,1]^3, origins in [-4,4]^3, rays aimed at barycentrics in
// [-0.25, 1.25] or inside the triangle (about half hit), direction lengths
// from 0.1 to 10, one ray in eight pointing away and one in four with a
// finite t_max.
RandomCase random_case(Random& rng) {
  RandomCase c;
  c.p0 = rng.box(-1.0f, 1.0f);
  c.p1 = rng.box(-1.0f, 1.0f);
  c.p2 = rng.box(-1.0f, 1.0f);
  c.ray.origin = rng.box(-4.0f, 4.0f);
  float a = rng.range(-0.25f, 1.25f);
  float b = rng.range(-0.25f, 1.25f);
  if (rng.below(2) == 0) {
    // Half the rays aim inside: fold the unit square onto the triangle.
    a = rng.unit();
    b = rng.unit();
    if (a + b > 1.0f) {
      a = 1.0f - a;
      b = 1.0f - b;
    }
  }
  const Vec3 target = c.p0 + a * (c.p1 - c.p0) + b * (c.p2 - c.p0);
  c.ray.direction = (target - c.ray.origin) * rng.range(0.1f, 10.0f);
  if (rng.below(8) == 0) c.ray.direction = -c.ray.direction;
  if (rng.below(4) == 0) c.ray.t_max = rng.range(0.0f, 2.0f);
  return c;
}

struct Agreement {
  int compared = 0, skipped = 0, hits = 0, disagreements = 0;
  double max_t_error = 0.0, max_uv_error = 0.0;
  // Over every hit away from a boundary, however ill-conditioned: the error
  // in units of float epsilon times the condition number.
  double max_scaled_error = 0.0;
};

constexpr double kFloatEpsilon = std::numeric_limits<float>::epsilon();

void compare_with_reference(TriangleTest test, const RandomCase& c, Agreement& agreement) {
  const Reference ref = solve_in_double(c.ray, c.p0, c.p1, c.p2);
  if (ref.solvable && boundary_margin(ref, c.ray) >= kEdgeMargin && reference_hits(ref, c.ray)) {
    TriangleHit hit{};
    if (intersect(test, c.ray, c.p0, c.p1, c.p2, hit)) {
      const double error = std::max({relative_error(static_cast<double>(hit.t), ref.t),
                                     std::abs(static_cast<double>(hit.u) - ref.u),
                                     std::abs(static_cast<double>(hit.v) - ref.v)});
      agreement.max_scaled_error =
          std::max(agreement.max_scaled_error, error / (kFloatEpsilon * ref.condition));
    }
  }
  if (!well_conditioned(ref, c.ray)) {
    ++agreement.skipped;
    return;
  }
  ++agreement.compared;
  TriangleHit hit{};
  const bool hits = intersect(test, c.ray, c.p0, c.p1, c.p2, hit);
  if (hits != reference_hits(ref, c.ray)) {
    ++agreement.disagreements;
    return;
  }
  if (!hits) return;
  ++agreement.hits;
  agreement.max_t_error = std::max(agreement.max_t_error, relative_error(static_cast<double>(hit.t), ref.t));
  agreement.max_uv_error = std::max({agreement.max_uv_error, std::abs(static_cast<double>(hit.u) - ref.u),
                                     std::abs(static_cast<double>(hit.v) - ref.v)});
}

TEST(TriangleIntersectRandom, BothTestsMatchADoublePrecisionReference) {
  for (TriangleTest test : kBothTests) {
    Random rng(12345);
    Agreement agreement;
    for (int i = 0; i < 100000; ++i) compare_with_reference(test, random_case(rng), agreement);
    std::printf(
        "%s: %d compared (%d hits), %d skipped (near a boundary or condition > %g), max t error %.3g, "
        "max u/v error %.3g; all hits: max error %.3g x epsilon x condition\n",
        name(test), agreement.compared, agreement.hits, agreement.skipped, kMaxCondition,
        agreement.max_t_error, agreement.max_uv_error, agreement.max_scaled_error);
    EXPECT_EQ(agreement.disagreements, 0) << name(test);
    EXPECT_GT(agreement.hits, 25000) << name(test);
    EXPECT_GT(agreement.compared, 50000) << name(test);
    // Over all hits, the error stays a small multiple of float epsilon times
    // the reference's condition number (measured: 1.2 fast, 0.6 watertight).
    EXPECT_LE(agreement.max_scaled_error, 4.0) << name(test);
    EXPECT_LE(agreement.max_t_error, kTolerance) << name(test);
    EXPECT_LE(agreement.max_uv_error, kTolerance) << name(test);
  }
}

TEST(TriangleIntersectRandom, FastAndWatertightAgree) {
  Random rng(777);
  int compared = 0, both_hit = 0;
  for (int i = 0; i < 100000; ++i) {
    const RandomCase c = random_case(rng);
    const Reference ref = solve_in_double(c.ray, c.p0, c.p1, c.p2);
    if (!well_conditioned(ref, c.ray)) continue;
    ++compared;
    TriangleHit fast{}, tight{};
    const bool fast_hits = intersect(TriangleTest::kFast, c.ray, c.p0, c.p1, c.p2, fast);
    const bool tight_hits = intersect(TriangleTest::kWatertight, c.ray, c.p0, c.p1, c.p2, tight);
    ASSERT_EQ(fast_hits, tight_hits) << "case " << i;
    if (!fast_hits) continue;
    ++both_hit;
    EXPECT_LE(relative_error(static_cast<double>(fast.t), static_cast<double>(tight.t)), kTolerance);
    EXPECT_NEAR(fast.u, tight.u, kTolerance);
    EXPECT_NEAR(fast.v, tight.v, kTolerance);
  }
  EXPECT_GT(compared, 50000);
  EXPECT_GT(both_hit, 25000);
}

// ---------------------------------------------------------------------------
// Hand-built edge cases.

// A triangle in the plane z = 2 whose edge functions are powers of two, so t
// comes out exactly 2 for the ray from the origin along +z.
const Vec3 kQ0{-1.0f, -1.0f, 2.0f}, kQ1{3.0f, -1.0f, 2.0f}, kQ2{-1.0f, 3.0f, 2.0f};

Ray make_ray(const Vec3& origin, const Vec3& direction, float t_min = 0.0f, float t_max = kInf) {
  Ray r;
  r.origin = origin;
  r.direction = direction;
  r.t_min = t_min;
  r.t_max = t_max;
  return r;
}

TEST(TriangleIntersectEdgeCases, HandCheckedHitAndBarycentrics) {
  // Hit point (0,0,2) = (1-u-v) q0 + u q1 + v q2 with u = v = 0.25.
  for (TriangleTest test : kBothTests) {
    TriangleHit hit{};
    ASSERT_TRUE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}), kQ0, kQ1, kQ2, hit)) << name(test);
    EXPECT_EQ(hit.t, 2.0f) << name(test);
    EXPECT_EQ(hit.u, 0.25f) << name(test);
    EXPECT_EQ(hit.v, 0.25f) << name(test);
    // A direction of length 4 quarters t: t is along the ray as given.
    ASSERT_TRUE(intersect(test, make_ray({0, 0, 0}, {0, 0, 4}), kQ0, kQ1, kQ2, hit)) << name(test);
    EXPECT_EQ(hit.t, 0.5f) << name(test);
  }
}

TEST(TriangleIntersectEdgeCases, TMinInclusiveTMaxExclusive) {
  const float after = std::nextafter(2.0f, kInf);
  for (TriangleTest test : kBothTests) {
    TriangleHit hit{};
    EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, 2.0f), kQ0, kQ1, kQ2, hit))
        << name(test);
    EXPECT_TRUE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, after), kQ0, kQ1, kQ2, hit))
        << name(test);
    EXPECT_TRUE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, 2.0f, kInf), kQ0, kQ1, kQ2, hit))
        << name(test);
    EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, after, kInf), kQ0, kQ1, kQ2, hit))
        << name(test);
    // Behind the origin (t = -2) is outside [0, inf); a negative t_min admits it.
    EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, -1}), kQ0, kQ1, kQ2, hit)) << name(test);
    ASSERT_TRUE(intersect(test, make_ray({0, 0, 0}, {0, 0, -1}, -kInf, kInf), kQ0, kQ1, kQ2, hit))
        << name(test);
    EXPECT_EQ(hit.t, -2.0f) << name(test);
    // The t_max argument, not ray.t_max, bounds the test (nearest-hit search).
    const Ray r = make_ray({0, 0, 0}, {0, 0, 1});
    EXPECT_FALSE(intersect_triangle_fast(r, 1.5f, kQ0, kQ1, kQ2, hit));
    EXPECT_FALSE(intersect_triangle_watertight(prepare_watertight(r), r, 1.5f, kQ0, kQ1, kQ2, hit));
  }
}

TEST(TriangleIntersectEdgeCases, BackFacesHitWithTheSameBarycentricConvention) {
  Random rng(5);
  for (TriangleTest test : kBothTests) {
    int checked = 0;
    for (int i = 0; i < 1000; ++i) {
      const Vec3 p0 = rng.box(-1, 1), p1 = rng.box(-1, 1), p2 = rng.box(-1, 1);
      const float a = rng.range(0.05f, 0.45f), b = rng.range(0.05f, 0.45f);
      const Vec3 target = p0 + a * (p1 - p0) + b * (p2 - p0);
      const Vec3 origin = target + rng.unit_vector() * 3.0f;
      const Ray ray = make_ray(origin, target - origin);
      const Reference ref = solve_in_double(ray, p0, p1, p2);
      if (ref.condition > kMaxCondition) continue;
      ++checked;
      TriangleHit front{}, back{};
      // Swapping p1 and p2 flips the face and swaps the roles of u and v:
      // u is always the weight of the second vertex, v of the third.
      ASSERT_TRUE(intersect(test, ray, p0, p1, p2, front)) << name(test) << " " << i;
      ASSERT_TRUE(intersect(test, ray, p0, p2, p1, back)) << name(test) << " " << i;
      EXPECT_NEAR(front.t, ref.t, kTolerance);
      EXPECT_NEAR(back.t, ref.t, kTolerance);
      EXPECT_NEAR(front.u, ref.u, kTolerance);
      EXPECT_NEAR(front.v, ref.v, kTolerance);
      EXPECT_NEAR(back.u, ref.v, kTolerance);
      EXPECT_NEAR(back.v, ref.u, kTolerance);
      // The aimed-at barycentrics, up to the rounding of the target point.
      EXPECT_NEAR(front.u, a, 1e-4f);
      EXPECT_NEAR(front.v, b, 1e-4f);
    }
    EXPECT_GT(checked, 500) << name(test);
  }
}

TEST(TriangleIntersectEdgeCases, ParallelRaysMiss) {
  for (TriangleTest test : kBothTests) {
    TriangleHit hit{};
    // In the plane of the triangle, through its interior, from each axis.
    EXPECT_FALSE(intersect(test, make_ray({-5, 0, 2}, {1, 0, 0}), kQ0, kQ1, kQ2, hit)) << name(test);
    EXPECT_FALSE(intersect(test, make_ray({0, -5, 2}, {0, 1, 0}), kQ0, kQ1, kQ2, hit)) << name(test);
    EXPECT_FALSE(intersect(test, make_ray({-5, -5, 2}, {1, 1, 0}), kQ0, kQ1, kQ2, hit)) << name(test);
    // Parallel, off the plane.
    EXPECT_FALSE(intersect(test, make_ray({-5, 0, 1}, {1, 0, 0}), kQ0, kQ1, kQ2, hit)) << name(test);
  }
}

TEST(TriangleIntersectEdgeCases, ZeroAreaTrianglesNeverHit) {
  // Exactly representable collinear points and repeated vertices, hit by
  // rays from many directions aimed exactly at points of the segment.
  const Vec3 a{-1.0f, 0.5f, 2.0f}, b{1.0f, 0.5f, 2.0f}, mid{0.0f, 0.5f, 2.0f};
  const Vec3 diagonal_a{0.0f, 0.0f, 0.0f}, diagonal_b{2.0f, 2.0f, 2.0f}, diagonal_mid{1.0f, 1.0f, 1.0f};
  struct Degenerate {
    Vec3 p0, p1, p2;
  };
  const Degenerate triangles[] = {{a, b, mid},
                                  {a, mid, b},
                                  {a, a, b},
                                  {a, b, b},
                                  {b, a, a},
                                  {a, a, a},
                                  {diagonal_a, diagonal_b, diagonal_mid},
                                  {diagonal_mid, diagonal_a, diagonal_b},
                                  {diagonal_a, diagonal_a, diagonal_b}};
  Random rng(99);
  int fast_hits = 0, watertight_hits = 0;
  for (const Degenerate& tri : triangles) {
    for (int i = 0; i < 2000; ++i) {
      const Vec3 target = glm::mix(tri.p0, tri.p1, rng.unit());
      const Ray ray = make_ray(target + rng.unit_vector() * 4.0f, -rng.unit_vector());
      const Ray aimed = make_ray(ray.origin, target - ray.origin);
      TriangleHit hit{};
      watertight_hits += intersect(TriangleTest::kWatertight, aimed, tri.p0, tri.p1, tri.p2, hit) ? 1 : 0;
      fast_hits += intersect(TriangleTest::kFast, aimed, tri.p0, tri.p1, tri.p2, hit) ? 1 : 0;
    }
  }
  std::printf("degenerate: fast %d watertight %d\n", fast_hits, watertight_hits);
  EXPECT_EQ(fast_hits, 0);
  EXPECT_EQ(watertight_hits, 0);
}

TEST(TriangleIntersectEdgeCases, NonFiniteInputNeverHits) {
  const float bad_values[] = {kNaN, kInf, -kInf};
  for (TriangleTest test : kBothTests) {
    for (float bad : bad_values) {
      for (int vertex = 0; vertex < 3; ++vertex) {
        for (int axis = 0; axis < 3; ++axis) {
          Vec3 p[3] = {kQ0, kQ1, kQ2};
          p[vertex][axis] = bad;
          // Rays from several origins aimed at the triangle's interior.
          for (const Vec3 origin : {Vec3(0, 0, 0), Vec3(0.3f, -0.2f, 10.0f), Vec3(-4, 1, 2.5f)}) {
            TriangleHit hit{};
            const Ray ray = make_ray(origin, Vec3(0.1f, 0.2f, 2.0f) - origin);
            EXPECT_FALSE(intersect(test, ray, p[0], p[1], p[2], hit))
                << name(test) << " value " << bad << " vertex " << vertex << " axis " << axis;
          }
        }
      }
      // A bad ray.
      TriangleHit hit{};
      EXPECT_FALSE(intersect(test, make_ray({bad, 0, 0}, {0, 0, 1}), kQ0, kQ1, kQ2, hit)) << name(test);
      EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, bad, 1}), kQ0, kQ1, kQ2, hit)) << name(test);
      if (bad != -kInf) {  // t_min = -inf is a valid (unbounded) range
        EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, bad, kInf), kQ0, kQ1, kQ2, hit))
            << name(test);
      }
    }
    TriangleHit hit{};
    EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, 0}), kQ0, kQ1, kQ2, hit)) << name(test);
    EXPECT_FALSE(intersect(test, make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, kNaN), kQ0, kQ1, kQ2, hit))
        << name(test);
  }
}

// Random hits on a triangle of the given size placed at `center`, the ray
// origin within `reach` of it: every hit must be found with the reference's
// t and barycentrics.
void check_scale(float size, const Vec3& center, float reach) {
  Random rng(31);
  for (TriangleTest test : kBothTests) {
    int compared = 0, hit_count = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 p0 = center + size * rng.box(-1, 1), p1 = center + size * rng.box(-1, 1),
                 p2 = center + size * rng.box(-1, 1);
      const float a = rng.range(0.0f, 1.0f), b = rng.range(0.0f, 1.0f);
      if (a + b > 1.0f) continue;
      const Vec3 origin = center + reach * rng.box(-1, 1);
      const Ray ray = make_ray(origin, p0 + a * (p1 - p0) + b * (p2 - p0) - origin);
      const Reference ref = solve_in_double(ray, p0, p1, p2);
      if (!well_conditioned(ref, ray)) continue;
      ++compared;
      TriangleHit hit{};
      const bool hits = intersect(test, ray, p0, p1, p2, hit);
      // The rounded target may fall just outside: the reference decides.
      ASSERT_EQ(hits, reference_hits(ref, ray)) << name(test) << " size " << size << " case " << i;
      if (!hits) continue;
      ++hit_count;
      EXPECT_LE(relative_error(static_cast<double>(hit.t), ref.t), kTolerance)
          << name(test) << " size " << size;
      EXPECT_NEAR(static_cast<double>(hit.u), ref.u, kTolerance) << name(test) << " size " << size;
      EXPECT_NEAR(static_cast<double>(hit.v), ref.v, kTolerance) << name(test) << " size " << size;
    }
    EXPECT_GT(compared, 500) << name(test);
    EXPECT_GT(hit_count, compared * 9 / 10) << name(test);
  }
}

TEST(TriangleIntersectEdgeCases, TinyHugeAndFarTriangles) {
  check_scale(1e-3f, Vec3(0.0f), 4e-3f);
  check_scale(1e4f, Vec3(0.0f), 4e4f);
  check_scale(1.0f, Vec3(1e5f, -2e4f, 3e4f), 4.0f);
}

// ---------------------------------------------------------------------------
// Watertightness: rays aimed exactly at shared edges and vertices.

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> indices;  // three per triangle

  std::size_t triangle_count() const { return indices.size() / 3; }
  // Whether any triangle reports a hit, and the nearest one.
  bool any_hit(TriangleTest test, const Ray& ray) const {
    TriangleHit hit{};
    for (std::size_t i = 0; i < triangle_count(); ++i) {
      if (intersect(test, ray, positions[indices[3 * i]], positions[indices[3 * i + 1]],
                    positions[indices[3 * i + 2]], hit)) {
        return true;
      }
    }
    return false;
  }
};

// An n x n quad grid over [0, n]^2 with jittered vertices (xy by up to 0.3,
// height up to 0.2) and each quad split along a random diagonal, so the
// edges meet at irregular angles and valences.
Mesh jittered_grid(int n, Random& rng) {
  Mesh mesh;
  const auto index = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      mesh.positions.emplace_back(static_cast<float>(i) + rng.range(-0.3f, 0.3f),
                                  static_cast<float>(j) + rng.range(-0.3f, 0.3f), rng.range(0.0f, 0.2f));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      if (rng.below(2) == 0) {
        mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
      } else {
        mesh.indices.insert(mesh.indices.end(), {a, b, d, b, c, d});
      }
    }
  }
  return mesh;
}

// 16 triangles around a raised centre vertex with jittered rim radii.
Mesh jittered_fan(Random& rng) {
  Mesh mesh;
  mesh.positions.emplace_back(0.1f, -0.05f, 0.15f);
  constexpr int kSpokes = 16;
  for (int k = 0; k < kSpokes; ++k) {
    const float angle = static_cast<float>(k) * (6.2831853f / kSpokes) + rng.range(-0.1f, 0.1f);
    const float radius = rng.range(0.7f, 1.3f);
    mesh.positions.emplace_back(radius * std::cos(angle), radius * std::sin(angle), rng.range(-0.05f, 0.05f));
  }
  for (std::uint32_t k = 0; k < kSpokes; ++k) {
    mesh.indices.insert(mesh.indices.end(), {0u, 1u + k, 1u + (k + 1) % kSpokes});
  }
  return mesh;
}

// A ray through `target` from a random direction at least 44 degrees off the
// xy plane, from above or below, from a random distance so origins and
// directions vary in their low bits. Both meshes are height fields over xy
// with slopes below 30 degrees, so such a ray crosses the surface near the
// target instead of grazing past a ridge: it must hit.
Ray ray_through(const Vec3& target, Random& rng) {
  Vec3 dir = rng.unit_vector();
  while (std::abs(dir.z) < 0.7f) dir = rng.unit_vector();
  const Vec3 origin = target - rng.range(2.0f, 20.0f) * dir;
  return make_ray(origin, target - origin);
}

struct LeakCount {
  int rays = 0, fast_leaks = 0, watertight_leaks = 0;
};

// Rays at points on the interior edges (float lerp of the endpoints, which is
// generally not exactly on the edge) and at the interior vertices.
void shoot_at_shared_features(const Mesh& mesh, const std::vector<std::uint32_t>& interior_vertices,
                              const std::vector<std::pair<std::uint32_t, std::uint32_t>>& interior_edges,
                              int rays_per_feature, Random& rng, LeakCount& count) {
  const auto shoot = [&](const Vec3& target) {
    const Ray ray = ray_through(target, rng);
    ++count.rays;
    if (!mesh.any_hit(TriangleTest::kWatertight, ray)) ++count.watertight_leaks;
    if (!mesh.any_hit(TriangleTest::kFast, ray)) ++count.fast_leaks;
  };
  for (std::uint32_t v : interior_vertices) {
    for (int r = 0; r < rays_per_feature; ++r) shoot(mesh.positions[v]);
  }
  for (const auto& [a, b] : interior_edges) {
    for (int r = 0; r < rays_per_feature; ++r) {
      shoot(glm::mix(mesh.positions[a], mesh.positions[b], rng.unit()));
    }
  }
}

// Edges used by two triangles.
std::vector<std::pair<std::uint32_t, std::uint32_t>> shared_edges(const Mesh& mesh) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = mesh.indices[3 * t + e], b = mesh.indices[3 * t + (e + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> shared;
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges[i] == edges[i - 1]) shared.push_back(edges[i]);
  }
  return shared;
}

// prepare_common_origin8 (a leaf's triangles eight at a time,
// traverse/large_packet.cpp) gives each lane what prepare_common_origin gives
// its triangle, bit for bit: small, huge, far, degenerate and non-finite
// corners, origins near and far.
TEST(TriangleIntersectEdgeCases, CommonOriginTermsEightAtATimeMatchOneAtATime) {
  Random rng(41);
  const auto bits = [](float x) { return std::bit_cast<std::uint32_t>(x); };
  const auto same = [&](const Vec3& a, const Vec3& b) {
    return bits(a.x) == bits(b.x) && bits(a.y) == bits(b.y) && bits(a.z) == bits(b.z);
  };
  const float specials[] = {0.0f, -0.0f, kInf, -kInf, kNaN, 3e38f, 1e-40f};
  int compared = 0;
  for (int batch = 0; batch < 400; ++batch) {
    const float scale = std::pow(10.0f, rng.range(-4.0f, 5.0f));
    const Vec3 origin = scale * rng.box(-2.0f, 2.0f);
    alignas(32) float p[3][3][8];
    Vec3 corners[8][3];
    for (int i = 0; i < 8; ++i) {
      const Vec3 centre = scale * rng.box(-1.0f, 1.0f);
      for (int k = 0; k < 3; ++k) {
        Vec3 c = centre + 0.01f * scale * rng.box(-1.0f, 1.0f);
        if (k == 2 && i == 3) c = corners[i][0];  // a degenerate triangle
        if (batch % 5 == 0 && rng.below(6) == 0) c[static_cast<int>(rng.below(3))] = specials[rng.below(7)];
        corners[i][k] = c;
        p[k][0][i] = c.x;
        p[k][1][i] = c.y;
        p[k][2][i] = c.z;
      }
    }
    CommonOriginLanes8 lanes;
    prepare_common_origin8(origin, p, lanes);
    for (int i = 0; i < 8; ++i) {
      const CommonOriginTriangle want = prepare_common_origin(origin, corners[i][0], corners[i][1], corners[i][2]);
      const CommonOriginTriangle got = lanes.at(i);
      ASSERT_TRUE(same(got.e1, want.e1) && same(got.e2, want.e2) && same(got.tv, want.tv) && same(got.q, want.q) &&
                  bits(got.t_numerator) == bits(want.t_numerator))
          << "batch " << batch << " lane " << i;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 3200);
}

TEST(TriangleIntersectWatertight, NoLeaksThroughAJitteredGrid) {
  Random rng(2024);
  constexpr int kN = 8;
  const Mesh grid = jittered_grid(kN, rng);
  std::vector<std::uint32_t> interior_vertices;
  for (int j = 1; j < kN; ++j) {
    for (int i = 1; i < kN; ++i) interior_vertices.push_back(static_cast<std::uint32_t>(j * (kN + 1) + i));
  }
  const auto edges = shared_edges(grid);
  ASSERT_EQ(edges.size(), static_cast<std::size_t>(3 * kN * kN - 2 * kN));  // interior edges + diagonals
  LeakCount count;
  shoot_at_shared_features(grid, interior_vertices, edges, 60, rng, count);
  std::printf("grid: %d rays at shared edges and vertices, fast leaks %d, watertight leaks %d\n", count.rays,
              count.fast_leaks, count.watertight_leaks);
  EXPECT_EQ(count.watertight_leaks, 0);
  EXPECT_GT(count.rays, 10000);
}

TEST(TriangleIntersectWatertight, NoLeaksThroughAFan) {
  Random rng(7);
  const Mesh fan = jittered_fan(rng);
  const auto edges = shared_edges(fan);
  ASSERT_EQ(edges.size(), 16u);  // the spokes
  LeakCount count;
  shoot_at_shared_features(fan, {0u}, edges, 400, rng, count);
  std::printf("fan: %d rays at the centre and the spokes, fast leaks %d, watertight leaks %d\n", count.rays,
              count.fast_leaks, count.watertight_leaks);
  EXPECT_EQ(count.watertight_leaks, 0);
}

// A closed, star-shaped mesh: an octahedron subdivided n times per edge,
// projected onto a sphere with jittered radii (0.9 to 1.1). Vertices on the
// octahedron's edges are shared between faces through their integer key.
Mesh jittered_octasphere(int n, Random& rng) {
  Mesh mesh;
  std::map<std::array<int, 3>, std::uint32_t> index_of;
  const auto vertex = [&](int x, int y, int z) {
    const std::array<int, 3> key{x, y, z};
    const auto found = index_of.find(key);
    if (found != index_of.end()) return found->second;
    const Vec3 direction =
        glm::normalize(Vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)));
    mesh.positions.push_back(direction * rng.range(0.9f, 1.1f));
    const auto index = static_cast<std::uint32_t>(mesh.positions.size() - 1);
    index_of.emplace(key, index);
    return index;
  };
  for (int face = 0; face < 8; ++face) {
    const int sx = (face & 1) ? -1 : 1, sy = (face & 2) ? -1 : 1, sz = (face & 4) ? -1 : 1;
    const auto at = [&](int i, int j) { return vertex(sx * i, sy * j, sz * (n - i - j)); };
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i + j < n; ++i) {
        mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 2 <= n)
          mesh.indices.insert(mesh.indices.end(), {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  }
  return mesh;
}

// Rays from random points near the centre, in every direction, aimed at the
// vertices and at float-lerped points of the edges: from inside a closed
// surface every ray must leave through it.
TEST(TriangleIntersectWatertight, NoLeaksOutOfAClosedMesh) {
  Random rng(99);
  constexpr int kN = 6;
  const Mesh sphere = jittered_octasphere(kN, rng);
  ASSERT_EQ(sphere.triangle_count(), static_cast<std::size_t>(8 * kN * kN));
  ASSERT_EQ(sphere.positions.size(), static_cast<std::size_t>(4 * kN * kN + 2));
  const auto edges = shared_edges(sphere);
  ASSERT_EQ(edges.size(), sphere.triangle_count() * 3 / 2);  // closed: every edge shared
  LeakCount count;
  const auto shoot = [&](const Vec3& target) {
    const Vec3 origin = rng.box(-0.3f, 0.3f);
    const Ray ray = make_ray(origin, target - origin);
    ++count.rays;
    if (!sphere.any_hit(TriangleTest::kWatertight, ray)) ++count.watertight_leaks;
    if (!sphere.any_hit(TriangleTest::kFast, ray)) ++count.fast_leaks;
  };
  for (int r = 0; r < 10; ++r) {
    for (const Vec3& p : sphere.positions) shoot(p);
    for (const auto& [a, b] : edges) shoot(glm::mix(sphere.positions[a], sphere.positions[b], rng.unit()));
  }
  std::printf("closed mesh: %d rays from inside at edges and vertices, fast leaks %d, watertight leaks %d\n",
              count.rays, count.fast_leaks, count.watertight_leaks);
  EXPECT_EQ(count.watertight_leaks, 0);
}

// The two triangles that share each interior edge, tested one at a time with
// rays at float-lerped points of the edge. The lerped point is generally a
// rounding step off the exact edge, so the edge function is tiny but not
// zero and only one side claims the ray; when the point lands exactly on the
// edge both do. The property that always holds is "at least one", and when
// both hit they agree on t.
TEST(TriangleIntersectWatertight, SharedEdgeIsClaimedByAtLeastOneSide) {
  Random rng(31337);
  constexpr int kN = 6;
  const Mesh grid = jittered_grid(kN, rng);
  int rays = 0, both = 0, fast_neither = 0;
  double max_t_gap = 0.0;
  for (const auto& [a, b] : shared_edges(grid)) {
    std::vector<std::size_t> sides;
    for (std::size_t t = 0; t < grid.triangle_count(); ++t) {
      int found = 0;
      for (int k = 0; k < 3; ++k)
        found += (grid.indices[3 * t + k] == a || grid.indices[3 * t + k] == b) ? 1 : 0;
      if (found == 2) sides.push_back(t);
    }
    ASSERT_EQ(sides.size(), 2u);
    const auto corner = [&](std::size_t t, int k) { return grid.positions[grid.indices[3 * t + k]]; };
    for (int r = 0; r < 100; ++r) {
      const Ray ray = ray_through(glm::mix(grid.positions[a], grid.positions[b], rng.unit()), rng);
      TriangleHit h0{}, h1{};
      const bool hit0 = intersect(TriangleTest::kWatertight, ray, corner(sides[0], 0), corner(sides[0], 1),
                                  corner(sides[0], 2), h0);
      const bool hit1 = intersect(TriangleTest::kWatertight, ray, corner(sides[1], 0), corner(sides[1], 1),
                                  corner(sides[1], 2), h1);
      ++rays;
      ASSERT_TRUE(hit0 || hit1) << "edge " << a << "-" << b << " ray " << r;
      if (hit0 && hit1) {
        ++both;
        max_t_gap = std::max(max_t_gap, relative_error(static_cast<double>(h0.t), static_cast<double>(h1.t)));
      }
      const bool fast0 = intersect(TriangleTest::kFast, ray, corner(sides[0], 0), corner(sides[0], 1),
                                   corner(sides[0], 2), h0);
      const bool fast1 = intersect(TriangleTest::kFast, ray, corner(sides[1], 0), corner(sides[1], 1),
                                   corner(sides[1], 2), h1);
      fast_neither += (!fast0 && !fast1) ? 1 : 0;
    }
  }
  std::printf(
      "shared edges: %d rays, watertight hit both sides %d times (max t gap %.3g), fast hit neither %d\n",
      rays, both, max_t_gap, fast_neither);
  EXPECT_LE(max_t_gap, 1e-6);
}

// A ray exactly through a shared edge (all coordinates exact, ray along an
// axis so the shear is trivial): the edge function is exactly zero in both
// triangles, both hit, at the same t, with the opposite vertex weighted 0.
TEST(TriangleIntersectWatertight, ExactSharedEdgeHitsBothSidesAtTheSameT) {
  const Vec3 e0{0, 0, 0}, e1{2, 2, 2}, left{2, 0, 1}, right{0, 2, -1};
  for (TriangleTest test : kBothTests) {
    for (const Vec3 dir : {Vec3(0, 0, -1), Vec3(0, 0, 1)}) {
      const Ray ray = make_ray(Vec3(1, 1, 1) - 4.0f * dir, dir);
      TriangleHit a{}, b{};
      ASSERT_TRUE(intersect(test, ray, e0, e1, left, a)) << name(test);
      ASSERT_TRUE(intersect(test, ray, e1, e0, right, b)) << name(test);
      EXPECT_EQ(a.t, 4.0f) << name(test);
      EXPECT_EQ(b.t, 4.0f) << name(test);
      EXPECT_EQ(a.v, 0.0f) << name(test);  // weight of the vertex off the edge
      EXPECT_EQ(b.v, 0.0f) << name(test);
      EXPECT_FLOAT_EQ(a.u, 0.5f) << name(test);
      EXPECT_FLOAT_EQ(b.u, 0.5f) << name(test);
    }
  }
}

// Not a test: ns per ray-triangle test, median of 5 runs (about half hits).
// Run with --gtest_also_run_disabled_tests.
// 1M tests cycling over `kDistinct` random pairs: 1M distinct pairs stream
// from memory; 16k stay in cache and show the arithmetic alone (traversal
// mostly tests cached triangles).
void benchmark(int kDistinct) {
  Random rng(4242);
  constexpr int kCount = 1 << 20;
  std::vector<RandomCase> cases;
  cases.reserve(kDistinct);
  for (int i = 0; i < kDistinct; ++i) cases.push_back(random_case(rng));
  std::vector<WatertightRay> prepared;
  prepared.reserve(kCount);
  for (const RandomCase& c : cases) prepared.push_back(prepare_watertight(c.ray));
  // Runs alternate between the two tests so both see the same machine load.
  std::vector<double> ns[2];
  int hits[2] = {0, 0};
  for (int run = 0; run < 5; ++run) {
    for (TriangleTest test : kBothTests) {
      const int which = test == TriangleTest::kFast ? 0 : 1;
      int found_count = 0;
      float checksum = 0.0f;
      const auto start = std::chrono::steady_clock::now();
      for (int k = 0; k < kCount; ++k) {
        const std::size_t i = static_cast<std::size_t>(k % kDistinct);
        const RandomCase& c = cases[i];
        TriangleHit hit{};
        const bool found =
            test == TriangleTest::kFast
                ? intersect_triangle_fast(c.ray, c.ray.t_max, c.p0, c.p1, c.p2, hit)
                : intersect_triangle_watertight(prepared[i], c.ray, c.ray.t_max, c.p0, c.p1, c.p2, hit);
        if (found) {
          ++found_count;
          checksum += hit.t;
        }
      }
      const auto stop = std::chrono::steady_clock::now();
      ns[which].push_back(std::chrono::duration<double, std::nano>(stop - start).count() / kCount);
      hits[which] = found_count;
      EXPECT_TRUE(std::isfinite(checksum));
    }
  }
  for (TriangleTest test : kBothTests) {
    const int which = test == TriangleTest::kFast ? 0 : 1;
    std::sort(ns[which].begin(), ns[which].end());
    std::printf("%s: %.2f ns per test (median of 5; min %.2f, max %.2f), %d hits of %d over %d pairs\n",
                name(test), ns[which][2], ns[which][0], ns[which][4], hits[which], kCount, kDistinct);
  }
}

TEST(TriangleIntersectBenchmark, DISABLED_NanosecondsPerTest) {
  benchmark(1 << 20);
  benchmark(1 << 14);
}

}  // namespace
}  // namespace sinew::rt
