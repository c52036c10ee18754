#include "raytrace/render/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

Status check_buffer(std::size_t size, std::size_t expected, std::string_view name) {
  if (size == 0 || size == expected) return {};
  return invalid_argument(name, std::to_string(size), "expected " + std::to_string(expected) + " entries");
}

// pbrt's gamma(n): a bound on n successive float roundings.
constexpr float gamma(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (static_cast<float>(n) * u) / (1.0f - static_cast<float>(n) * u);
}

float encode_srgb(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// Linear -> sRGB byte through a table: std::pow per channel per pixel cost
// more than the shading itself. 16384 entries keep the darkest steps
// (sRGB byte 1 is linear 3e-4) apart.
class SrgbTable {
 public:
  SrgbTable() {
    for (std::size_t i = 0; i < bytes_.size(); ++i) {
      const float linear = (static_cast<float>(i) + 0.5f) / static_cast<float>(bytes_.size());
      bytes_[i] = static_cast<std::uint8_t>(std::lround(encode_srgb(linear) * 255.0f));
    }
  }
  std::uint8_t operator()(float linear) const {
    const float scaled = std::clamp(linear, 0.0f, 1.0f) * static_cast<float>(bytes_.size() - 1);
    return bytes_[static_cast<std::size_t>(scaled)];  // callers pass no NaN (to_byte)
  }

 private:
  std::array<std::uint8_t, 16384> bytes_{};
};

// Built once at start-up, not behind a function-local static's guard, which
// every one of the three lookups per pixel paid.
const SrgbTable kSrgbTable;

std::uint8_t to_byte(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  return kSrgbTable(linear);
}

// The next float towards +inf (up) or -inf; infinities and NaN unchanged.
// std::nextafter's result for finite x, without the libm call per axis per
// shadow ray.
float next_float(float x, bool up) {
  if (!std::isfinite(x)) return x;
  if (x == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
  std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  bits = (x > 0.0f) == up ? bits + 1 : bits - 1;
  return std::bit_cast<float>(bits);
}

float max_abs_coordinate(const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

Vec3 light_vector(const Light& light, const Vec3& from) {
  return light.kind == Light::Kind::kPoint ? light.position - from : light.direction;
}

// Sums per-tile counters in tile order so the totals are deterministic.
void add(TraversalCounters& into, const TraversalCounters& from) {
  into.rays += from.rays;
  into.node_visits += from.node_visits;
  into.object_visits += from.object_visits;
  into.triangle_tests += from.triangle_tests;
}

}  // namespace

SurfacePoint surface_at(const Scene& scene, const Hit& hit, const Vec3& default_albedo) {
  SurfacePoint s;
  const Scene::ObjectSlot slot = scene.object_slots()[hit.instance_id];
  const float w = 1.0f - hit.u - hit.v;
  Vec3 p[3];
  Vec3 shading(0.0f);
  bool have_normals = false;
  if (slot.kind == Scene::ObjectKind::kCharacter) {
    const InstanceFrame& frame = scene.instances()[slot.index];
    const SkinnedMesh& mesh = *scene.characters()[frame.character].mesh;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int i = 0; i < 3; ++i) p[i] = frame.positions[v[static_cast<std::size_t>(i)]];
    if (!frame.normals.empty()) {
      shading = w * frame.normals[v[0]] + hit.u * frame.normals[v[1]] + hit.v * frame.normals[v[2]];
      have_normals = true;
    }
    s.albedo = default_albedo;
    if (hit.triangle_id < mesh.triangle_material.size()) {
      const std::uint32_t m = mesh.triangle_material[hit.triangle_id];
      if (m < mesh.material_colors.size()) s.albedo = mesh.material_colors[m];
    }
  } else {
    const StaticMeshDesc& mesh = scene.static_meshes()[slot.index].desc;
    const auto& v = mesh.triangles[hit.triangle_id];
    for (int i = 0; i < 3; ++i) p[i] = mesh.positions[v[static_cast<std::size_t>(i)]];
    s.albedo = default_albedo;
    const std::uint32_t m = mesh.triangle_material.empty() ? 0 : mesh.triangle_material[hit.triangle_id];
    if (m < mesh.material_colors.size()) s.albedo = mesh.material_colors[m];
  }
  s.position = w * p[0] + hit.u * p[1] + hit.v * p[2];
  // Bounds the rounding of `position` and, more to the point, of a triangle
  // test started from it: Moller-Trumbore forms origin - p0 in every axis,
  // so its error is relative to the largest vertex coordinate in any axis.
  // A per-axis bound is 0 across a floor at exactly y = 0, and a shadow ray
  // started one float above it hit the floor itself at t = -0.
  const float magnitude = std::max({max_abs_coordinate(p[0]), max_abs_coordinate(p[1]), max_abs_coordinate(p[2])});
  s.error = Vec3(gamma(7) * magnitude);
  const Vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
  const float length = glm::length(n);
  s.geometric_normal = length > 0.0f && std::isfinite(length) ? n / length : Vec3(0.0f, 0.0f, 1.0f);
  const float shading_length = have_normals ? glm::length(shading) : 0.0f;
  s.shading_normal = shading_length > 0.0f && std::isfinite(shading_length) ? shading / shading_length
                                                                             : s.geometric_normal;
  return s;
}

Vec3 offset_origin(const SurfacePoint& surface, const Vec3& toward) {
  const Vec3& n = surface.geometric_normal;
  const float distance = glm::dot(glm::abs(n), surface.error);
  Vec3 offset = distance * n;
  if (glm::dot(n, toward) < 0.0f) offset = -offset;
  Vec3 origin = surface.position + offset;
  // The addition itself rounds: step one more float away from the surface.
  for (int a = 0; a < 3; ++a) {
    if (offset[a] > 0.0f) origin[a] = next_float(origin[a], true);
    if (offset[a] < 0.0f) origin[a] = next_float(origin[a], false);
  }
  return origin;
}

namespace {

// One tile's working set, reused by each thread across tiles and frames:
// the tile's hits, primary directions and surfaces stay in cache from the
// primary rays through the shadow rays to the shading.
struct TileScratch {
  std::vector<Hit> hits;
  std::vector<Vec3> directions;  // unit primary directions
  std::vector<SurfacePoint> surfaces;
  std::vector<std::uint8_t> lit;
  void resize(std::size_t n) {
    if (hits.size() < n) {
      hits.resize(n);
      directions.resize(n);
      surfaces.resize(n);
      lit.resize(n);
    }
  }
};

TileScratch& tile_scratch() {
  thread_local TileScratch scratch;
  return scratch;
}

using Clock = std::chrono::steady_clock;

double nanoseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::nano>(to - from).count();
}

// Per tile: time spent in each phase and what it counted.
struct TileRecord {
  TraversalCounters primary;
  TraversalCounters shadow;
  std::uint64_t hits = 0;
  std::uint64_t shadowed = 0;
  double primary_ns = 0.0;
  double shadow_ns = 0.0;
  double shade_ns = 0.0;
};

}  // namespace

Expected<RenderStats> Renderer::render(const Scene& scene, const PinholeCamera& camera,
                                       const RenderSettings& settings, const FrameBuffers& buffers,
                                       JobSystem& jobs, PhaseTimers* timers) {
  if (buffers.width != camera.width() || buffers.height != camera.height()) {
    return invalid_argument("buffers.width x height",
                            std::to_string(buffers.width) + "x" + std::to_string(buffers.height),
                            "differs from the camera's image size");
  }
  if (settings.tile_size < 1) {
    return invalid_argument("settings.tile_size", std::to_string(settings.tile_size), "must be at least 1");
  }
  const std::size_t pixels = static_cast<std::size_t>(buffers.width) * static_cast<std::size_t>(buffers.height);
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.color_rgba8.size(), 4 * pixels, "buffers.color_rgba8"));
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.color_rgba32f.size(), 4 * pixels, "buffers.color_rgba32f"));
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.depth.size(), pixels, "buffers.depth"));
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.normal.size(), pixels, "buffers.normal"));
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.triangle_id.size(), pixels, "buffers.triangle_id"));
  SINEW_RETURN_IF_ERROR(check_buffer(buffers.instance_id.size(), pixels, "buffers.instance_id"));

  const bool want_color = !buffers.color_rgba8.empty() || !buffers.color_rgba32f.empty();
  const bool want_surface = want_color || !buffers.normal.empty();
  const bool want_shadows = want_color && settings.shadows;
  const std::size_t width = static_cast<std::size_t>(buffers.width);
  const int tile = settings.tile_size;
  const int tiles_x = (buffers.width + tile - 1) / tile;
  const int tiles_y = (buffers.height + tile - 1) / tile;
  const std::size_t tile_count = static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);
  std::vector<TileRecord> records(tile_count);
  const std::array<std::uint8_t, 4> background_bytes = {to_byte(settings.background.x), to_byte(settings.background.y),
                                                         to_byte(settings.background.z), 255};

  const auto start = Clock::now();
  jobs.parallel_for_tiles(buffers.width, buffers.height, tile, [&](const Tile& t) {
    TileRecord& record = records[static_cast<std::size_t>(t.index)];
    const int tw = t.x1 - t.x0;
    const auto local = [&](int x, int y) { return static_cast<std::size_t>((y - t.y0) * tw + (x - t.x0)); };
    const auto global = [&](int x, int y) { return static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x); };
    TileScratch& s = tile_scratch();
    s.resize(static_cast<std::size_t>(tw * (t.y1 - t.y0)));

    // Primary rays: nearest hits.
    const auto t0 = Clock::now();
    if (settings.packets) {
      // 4x2 pixel blocks; lanes outside the tile stay inactive.
      for (int y = t.y0; y < t.y1; y += 2) {
        for (int x = t.x0; x < t.x1; x += 4) {
          RayPacket packet;
          packet.active = 0;
          for (int lane = 0; lane < kPacketSize; ++lane) {
            const int px = x + lane % 4;
            const int py = y + lane / 4;
            if (px >= t.x1 || py >= t.y1) continue;
            const Ray ray = camera.ray(px, py);
            s.directions[local(px, py)] = ray.direction;
            packet.set(lane, ray);
            packet.active = static_cast<std::uint8_t>(packet.active | (1u << lane));
          }
          Hit lane_hits[kPacketSize];
          intersect_packet(scene, packet, settings.triangle_test, lane_hits, &record.primary);
          for (int lane = 0; lane < kPacketSize; ++lane) {
            if (packet.active & (1u << lane)) s.hits[local(x + lane % 4, y + lane / 4)] = lane_hits[lane];
          }
        }
      }
    } else {
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          const Ray ray = camera.ray(x, y);
          s.directions[local(x, y)] = ray.direction;
          s.hits[local(x, y)] = intersect(scene, ray, settings.triangle_test, &record.primary);
        }
      }
    }
    const auto t1 = Clock::now();

    // Surfaces (shading work), then one shadow ray per hit that faces the light.
    double shadow_ns = 0.0;
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        s.lit[k] = 1;
        if (!s.hits[k].valid()) continue;
        ++record.hits;
        if (want_surface) s.surfaces[k] = surface_at(scene, s.hits[k], settings.default_albedo);
      }
    }
    if (want_shadows) {
      const auto shadow_start = Clock::now();
      RayPacket pending;
      std::size_t pending_pixel[kPacketSize];
      int pending_count = 0;
      const auto flush = [&] {
        if (pending_count == 0) return;
        pending.active = static_cast<std::uint8_t>((1u << pending_count) - 1u);
        const std::uint8_t blocked = occluded_packet(scene, pending, settings.triangle_test, &record.shadow);
        for (int lane = 0; lane < pending_count; ++lane) {
          if (blocked & (1u << lane)) {
            s.lit[pending_pixel[lane]] = 0;
            ++record.shadowed;
          }
        }
        pending_count = 0;
      };
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          const std::size_t k = local(x, y);
          if (!s.hits[k].valid()) continue;
          const SurfacePoint& surface = s.surfaces[k];
          Vec3 facing = surface.geometric_normal;
          if (glm::dot(facing, s.directions[k]) > 0.0f) facing = -facing;
          const Vec3 to_light = light_vector(settings.light, surface.position);
          if (glm::dot(facing, to_light) <= 0.0f) {
            s.lit[k] = 0;  // the light is behind the surface: no ray needed
            continue;
          }
          Ray shadow;
          shadow.origin = offset_origin(surface, facing);
          shadow.direction = light_vector(settings.light, shadow.origin);
          shadow.t_min = 0.0f;
          shadow.t_max = settings.light.kind == Light::Kind::kPoint ? 1.0f : kInf;
          if (!settings.packets) {
            if (occluded(scene, shadow, settings.triangle_test, &record.shadow)) {
              s.lit[k] = 0;
              ++record.shadowed;
            }
            continue;
          }
          // Hits of a tile in scan order fill packets of eight shadow rays.
          pending.set(pending_count, shadow);
          pending_pixel[pending_count++] = k;
          if (pending_count == kPacketSize) flush();
        }
      }
      flush();
      shadow_ns = nanoseconds(shadow_start, Clock::now());
    }

    // Shading and the requested outputs.
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        const std::size_t i = global(x, y);
        const Hit& hit = s.hits[k];
        if (!buffers.triangle_id.empty()) buffers.triangle_id[i] = hit.triangle_id;
        if (!buffers.instance_id.empty()) buffers.instance_id[i] = hit.instance_id;
        if (!hit.valid()) {
          if (!buffers.depth.empty()) buffers.depth[i] = kInf;
          if (!buffers.normal.empty()) buffers.normal[i] = Vec3(0.0f);
          if (!buffers.color_rgba32f.empty()) {
            for (int c = 0; c < 3; ++c) buffers.color_rgba32f[4 * i + static_cast<std::size_t>(c)] = settings.background[c];
            buffers.color_rgba32f[4 * i + 3] = 1.0f;
          }
          if (!buffers.color_rgba8.empty()) {
            for (int c = 0; c < 4; ++c) buffers.color_rgba8[4 * i + static_cast<std::size_t>(c)] = background_bytes[static_cast<std::size_t>(c)];
          }
          continue;
        }
        if (!buffers.depth.empty()) buffers.depth[i] = hit.t * glm::length(s.directions[k]);
        if (!want_surface) continue;
        const SurfacePoint& surface = s.surfaces[k];
        Vec3 facing = surface.geometric_normal;
        if (glm::dot(facing, s.directions[k]) > 0.0f) facing = -facing;
        Vec3 n = surface.shading_normal;
        if (glm::dot(n, facing) < 0.0f) n = -n;
        if (!buffers.normal.empty()) buffers.normal[i] = n;
        if (!want_color) continue;
        const Vec3 l = glm::normalize(light_vector(settings.light, surface.position));
        const float lambert = s.lit[k] ? std::max(0.0f, glm::dot(n, l)) : 0.0f;
        const Vec3 linear = surface.albedo * (settings.ambient + settings.light.color * lambert);
        if (!buffers.color_rgba32f.empty()) {
          for (int c = 0; c < 3; ++c) buffers.color_rgba32f[4 * i + static_cast<std::size_t>(c)] = linear[c];
          buffers.color_rgba32f[4 * i + 3] = 1.0f;
        }
        if (!buffers.color_rgba8.empty()) {
          for (int c = 0; c < 3; ++c) buffers.color_rgba8[4 * i + static_cast<std::size_t>(c)] = to_byte(linear[c]);
          buffers.color_rgba8[4 * i + 3] = 255;
        }
      }
    }
    const auto t3 = Clock::now();
    record.primary_ns = nanoseconds(t0, t1);
    record.shadow_ns = shadow_ns;
    record.shade_ns = nanoseconds(t1, t3) - shadow_ns;
  });
  const double wall_ms = elapsed_ms(start);

  // Tile order keeps the sums deterministic.
  RenderStats stats;
  double primary_ns = 0.0, shadow_ns = 0.0, shade_ns = 0.0;
  for (const TileRecord& r : records) {
    add(stats.primary, r.primary);
    add(stats.shadow, r.shadow);
    stats.primary_hits += r.hits;
    stats.shadowed += r.shadowed;
    primary_ns += r.primary_ns;
    shadow_ns += r.shadow_ns;
    shade_ns += r.shade_ns;
  }
  stats.primary_rays = pixels;
  stats.shadow_rays = stats.shadow.rays;
  // The phases interleave within each tile: the wall time of the whole
  // render is split in proportion to the time the tiles spent in each.
  const double busy_ns = primary_ns + shadow_ns + shade_ns;
  if (busy_ns > 0.0) {
    stats.trace_primary_ms = wall_ms * primary_ns / busy_ns;
    stats.trace_shadow_ms = wall_ms * shadow_ns / busy_ns;
    stats.shade_ms = wall_ms * shade_ns / busy_ns;
  } else {
    stats.shade_ms = wall_ms;
  }

  if (timers) {
    timers->record("trace primary", stats.trace_primary_ms);
    timers->record("trace shadow", stats.trace_shadow_ms);
    timers->record("shade", stats.shade_ms);
  }
  return stats;
}

}  // namespace sinew::rt
