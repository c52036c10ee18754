#include "game_demo/arena.h"

#include <array>
#include <cmath>
#include <random>
#include <utility>

namespace sinew::demo {
namespace {

// [0, 1) from the top 24 bits: the same on every platform, unlike
// std::uniform_real_distribution.
float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

float in_range(std::mt19937& rng, float lo, float hi) { return lo + (hi - lo) * unit_float(rng); }

void add_quad(rt::StaticMeshDesc& mesh, const std::array<Vec3, 4>& corners, std::uint32_t material) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  for (const Vec3& c : corners) mesh.positions.push_back(c);
  mesh.triangles.push_back({base, base + 1, base + 2});
  mesh.triangles.push_back({base, base + 2, base + 3});
  mesh.triangle_material.push_back(material);
  mesh.triangle_material.push_back(material);
}

void add_box(rt::StaticMeshDesc& mesh, const Aabb& b, std::uint32_t material) {
  const Vec3 l = b.lower, u = b.upper;
  add_quad(mesh, {Vec3(l.x, l.y, l.z), Vec3(u.x, l.y, l.z), Vec3(u.x, u.y, l.z), Vec3(l.x, u.y, l.z)}, material);
  add_quad(mesh, {Vec3(l.x, l.y, u.z), Vec3(l.x, u.y, u.z), Vec3(u.x, u.y, u.z), Vec3(u.x, l.y, u.z)}, material);
  add_quad(mesh, {Vec3(l.x, l.y, l.z), Vec3(l.x, u.y, l.z), Vec3(l.x, u.y, u.z), Vec3(l.x, l.y, u.z)}, material);
  add_quad(mesh, {Vec3(u.x, l.y, l.z), Vec3(u.x, l.y, u.z), Vec3(u.x, u.y, u.z), Vec3(u.x, u.y, l.z)}, material);
  add_quad(mesh, {Vec3(l.x, u.y, l.z), Vec3(u.x, u.y, l.z), Vec3(u.x, u.y, u.z), Vec3(l.x, u.y, u.z)}, material);
  // No bottom face: it rests on the floor.
}

}  // namespace

Arena Arena::generate(std::uint32_t seed, int obstacle_count) {
  Arena arena;
  std::mt19937 rng(seed);
  int attempts = 0;
  while (static_cast<int>(arena.obstacles.size()) < obstacle_count && attempts++ < 10000) {
    const Vec3 c(in_range(rng, -10.0f, 10.0f), 0.0f, in_range(rng, -10.0f, 10.0f));
    const Vec3 half(in_range(rng, 0.4f, 1.2f), in_range(rng, 0.6f, 1.8f), in_range(rng, 0.4f, 1.2f));
    if (std::hypot(c.x, c.z) < 3.0f + std::max(half.x, half.z)) continue;  // the centre stays free
    const Aabb box{Vec3(c.x - half.x, 0.0f, c.z - half.z), Vec3(c.x + half.x, 2.0f * half.y, c.z + half.z)};
    bool overlaps = false;
    for (const Aabb& other : arena.obstacles) {
      overlaps = overlaps || (box.lower.x < other.upper.x + 1.5f && other.lower.x < box.upper.x + 1.5f &&
                              box.lower.z < other.upper.z + 1.5f && other.lower.z < box.upper.z + 1.5f);
    }
    if (overlaps) continue;  // keep walkable gaps between boxes
    arena.obstacles.push_back(box);
    arena.obstacle_colors.push_back(
        Vec3(in_range(rng, 0.25f, 0.8f), in_range(rng, 0.25f, 0.8f), in_range(rng, 0.25f, 0.8f)));
  }
  return arena;
}

std::vector<rt::StaticMeshDesc> Arena::static_meshes(float tile) const {
  rt::StaticMeshDesc ground;
  ground.material_colors = {Vec3(0.62f, 0.62f, 0.60f), Vec3(0.46f, 0.47f, 0.45f)};
  const int tiles = std::max(1, static_cast<int>(std::ceil(2.0f * ground_half_size / tile)));
  const float step = 2.0f * ground_half_size / static_cast<float>(tiles);
  for (int j = 0; j < tiles; ++j) {
    for (int i = 0; i < tiles; ++i) {
      const float x0 = -ground_half_size + step * static_cast<float>(i);
      const float z0 = -ground_half_size + step * static_cast<float>(j);
      const float x1 = x0 + step, z1 = z0 + step;
      // Counter-clockwise seen from above (+Y normal).
      add_quad(ground, {Vec3(x0, 0.0f, z0), Vec3(x0, 0.0f, z1), Vec3(x1, 0.0f, z1), Vec3(x1, 0.0f, z0)},
               static_cast<std::uint32_t>((i + j) % 2));
    }
  }
  std::vector<rt::StaticMeshDesc> meshes{std::move(ground)};
  if (obstacles.empty()) return meshes;
  rt::StaticMeshDesc boxes;
  for (std::size_t b = 0; b < obstacles.size(); ++b) {
    boxes.material_colors.push_back(obstacle_colors[b]);
    add_box(boxes, obstacles[b], static_cast<std::uint32_t>(b));
  }
  meshes.push_back(std::move(boxes));
  return meshes;
}

}  // namespace sinew::demo
