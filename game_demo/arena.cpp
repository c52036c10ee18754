#include "game_demo/arena.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace sinew::demo {
namespace {

constexpr int kTileSize = 32;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Slab test; returns the entry distance and the entry face's normal.
bool hit_box(const Aabb& box, const Ray& ray, float& t_hit, Vec3& n_hit) {
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  int axis = -1;
  float sign = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / ray.direction[a];
    float near = (box.lower[a] - ray.origin[a]) * inv;
    float far = (box.upper[a] - ray.origin[a]) * inv;
    const float s = inv < 0.0f ? 1.0f : -1.0f;
    if (near > far) std::swap(near, far);
    if (near > t0) {
      t0 = near;
      axis = a;
      sign = s;
    }
    t1 = std::min(t1, far);
    if (t0 > t1) return false;
  }
  if (axis < 0) return false;  // origin inside the box: not a visible surface
  t_hit = t0;
  n_hit = Vec3(0.0f);
  n_hit[axis] = sign;
  return true;
}

// Pinhole camera basis: forward = normalize(target - eye), right =
// normalize(cross(forward, up)), up' = cross(right, forward); pixel row 0 is
// the top of the image.
struct PinholeBasis {
  PinholeBasis(const Camera& c, int width, int height)
      : forward(glm::normalize(c.target - c.eye)),
        right(glm::normalize(glm::cross(forward, c.up))),
        up(glm::cross(right, forward)),
        tan_half(std::tan(glm::radians(c.fovy_degrees) * 0.5f)),
        aspect(float(width) / float(height)),
        w(width),
        h(height) {}

  Vec3 direction(int x, int y) const {
    const float sx = 2.0f * (float(x) + 0.5f) / float(w) - 1.0f;
    const float sy = 1.0f - 2.0f * (float(y) + 0.5f) / float(h);
    return glm::normalize(forward + sx * tan_half * aspect * right + sy * tan_half * up);
  }

  Vec3 forward, right, up;
  float tan_half, aspect;
  int w, h;
};

std::size_t pixel_index(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
}

}  // namespace

Arena Arena::generate(std::uint32_t seed, int obstacle_count) {
  Arena arena;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-9.0f, 9.0f);
  std::uniform_real_distribution<float> size(0.4f, 1.4f);
  std::uniform_real_distribution<float> hue(0.3f, 0.9f);
  while (static_cast<int>(arena.obstacles.size()) < obstacle_count) {
    const Vec3 c(pos(rng), 0.0f, pos(rng));
    if (glm::length(Vec3(c.x, 0, c.z)) < 3.0f) continue;  // keep the centre free for characters
    const Vec3 half(size(rng), size(rng) * 1.5f, size(rng));
    arena.obstacles.push_back({Vec3(c.x - half.x, 0.0f, c.z - half.z),
                               Vec3(c.x + half.x, 2.0f * half.y, c.z + half.z)});
    arena.obstacle_colors.push_back(Vec3(hue(rng), hue(rng), hue(rng)));
  }
  return arena;
}

void FrameBuffers::resize(int w, int h) {
  width = w;
  height = h;
  const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  t.assign(n, kInf);
  what.assign(n, -1);
  normal.assign(n, Vec3(0.0f));
  position.assign(n, Vec3(0.0f));
  lit.assign(n, 0);
  rgba.assign(n * 4, 0);
}

void render_arena(const Arena& arena, const Camera& camera, JobSystem& jobs, FrameBuffers& fb,
                  PhaseTimers& timers) {
  const int w = fb.width;
  const int h = fb.height;
  const PinholeBasis basis(camera, w, h);

  {
    ScopedPhase phase(timers, "trace primary");
    jobs.parallel_for_tiles(w, h, kTileSize, [&](const Tile& tile) {
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          Ray ray;
          ray.origin = camera.eye;
          ray.direction = basis.direction(x, y);
          float best = kInf;
          std::int32_t what = -1;
          Vec3 n(0.0f);
          if (ray.direction.y < 0.0f) {
            const float tg = -ray.origin.y / ray.direction.y;
            const Vec3 p = ray.at(tg);
            if (std::fabs(p.x) < arena.ground_half_size && std::fabs(p.z) < arena.ground_half_size) {
              best = tg;
              what = 0;
              n = Vec3(0, 1, 0);
            }
          }
          for (std::size_t i = 0; i < arena.obstacles.size(); ++i) {
            float tb = 0.0f;
            Vec3 nb;
            ray.t_max = best;
            if (hit_box(arena.obstacles[i], ray, tb, nb) && tb < best) {
              best = tb;
              what = static_cast<std::int32_t>(i + 1);
              n = nb;
            }
          }
          const std::size_t idx = pixel_index(x, y, w);
          fb.t[idx] = best;
          fb.position[idx] = ray.at(best);
          fb.what[idx] = what;
          fb.normal[idx] = n;
        }
      }
    });
  }
  {
    ScopedPhase phase(timers, "trace shadow");
    jobs.parallel_for_tiles(w, h, kTileSize, [&](const Tile& tile) {
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          const std::size_t idx = pixel_index(x, y, w);
          if (fb.what[idx] < 0) continue;
          const Vec3 p = fb.position[idx];
          Ray shadow;
          // Offset along the normal, scaled with the point's magnitude so the
          // offset stays above float spacing far from the origin.
          const float offset = 1e-4f * std::max(1.0f, glm::length(p));
          shadow.origin = p + offset * fb.normal[idx];
          shadow.direction = arena.light_position - shadow.origin;
          shadow.t_max = 1.0f;
          bool blocked = false;
          for (const Aabb& box : arena.obstacles) {
            float tb = 0.0f;
            Vec3 nb;
            if (hit_box(box, shadow, tb, nb)) {
              blocked = true;
              break;
            }
          }
          fb.lit[idx] = blocked ? 0 : 1;
        }
      }
    });
  }
  {
    ScopedPhase phase(timers, "shade");
    jobs.parallel_for_tiles(w, h, kTileSize, [&](const Tile& tile) {
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          const std::size_t idx = pixel_index(x, y, w);
          Vec3 c;
          if (fb.what[idx] < 0) {
            const float s = float(y) / float(h);
            c = glm::mix(Vec3(0.35f, 0.5f, 0.8f), Vec3(0.8f, 0.85f, 0.95f), s);
          } else {
            const Vec3 p = fb.position[idx];
            Vec3 albedo;
            if (fb.what[idx] == 0) {
              const bool odd = (int(std::floor(p.x)) + int(std::floor(p.z))) & 1;
              albedo = odd ? Vec3(0.55f) : Vec3(0.75f);
            } else {
              albedo = arena.obstacle_colors[static_cast<std::size_t>(fb.what[idx] - 1)];
            }
            const float diffuse = std::max(0.0f, glm::dot(fb.normal[idx], glm::normalize(arena.light_position - p)));
            c = albedo * (0.25f + 0.75f * diffuse * float(fb.lit[idx]));
          }
          for (int k = 0; k < 3; ++k) {
            fb.rgba[idx * 4 + static_cast<std::size_t>(k)] =
                static_cast<std::uint8_t>(std::clamp(c[k], 0.0f, 1.0f) * 255.0f + 0.5f);
          }
          fb.rgba[idx * 4 + 3] = 255;
        }
      }
    });
  }
}

}  // namespace sinew::demo
