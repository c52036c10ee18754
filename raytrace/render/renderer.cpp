#include "raytrace/render/renderer.h"
#include "raytrace/render/tile_scratch.h"

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

// One requested output: where pixel (x, y)'s `channels` elements start.
// Rows are `pitch` bytes apart, packed or the host's padded layout.
template <class T>
struct OutputPlane {
  std::byte* base = nullptr;  // null: not requested
  std::size_t pitch = 0;
  std::size_t channels = 1;

  bool wanted() const { return base != nullptr; }
  T* at(int x, int y) const {
    return reinterpret_cast<T*>(base + static_cast<std::size_t>(y) * pitch) + static_cast<std::size_t>(x) * channels;
  }
};

template <class T>
Expected<OutputPlane<T>> output_plane(std::span<T> span, std::size_t pitch, std::size_t channels, int width,
                                      int height, std::string_view name) {
  OutputPlane<T> plane;
  if (span.empty()) return plane;
  const std::size_t w = static_cast<std::size_t>(width);
  const std::size_t h = static_cast<std::size_t>(height);
  const std::size_t row_bytes = w * channels * sizeof(T);
  if (pitch == 0) {
    // Packed rows: the span is exactly the image.
    if (span.size() != w * h * channels) {
      return invalid_argument(name, std::to_string(span.size()),
                              "expected " + std::to_string(w * h * channels) + " entries");
    }
    pitch = row_bytes;
  } else {
    const std::string pitch_field = "row_pitch." + std::string(name.substr(name.find('.') + 1));
    if (pitch < row_bytes) {
      return invalid_argument(pitch_field, std::to_string(pitch),
                              "below one row of " + std::to_string(row_bytes) + " bytes");
    }
    if (pitch % alignof(T) != 0) {
      return invalid_argument(pitch_field, std::to_string(pitch),
                              "not a multiple of the element alignment " + std::to_string(alignof(T)));
    }
    const std::size_t needed = (h - 1) * pitch + row_bytes;
    if (span.size_bytes() < needed) {
      return invalid_argument(name, std::to_string(span.size_bytes()) + " bytes",
                              "the rows need " + std::to_string(needed) + " bytes at this pitch");
    }
  }
  plane.base = reinterpret_cast<std::byte*>(span.data());
  plane.pitch = pitch;
  plane.channels = channels;
  return plane;
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
  const std::span<const Light> lights =
      settings.lights.empty() ? std::span<const Light>(&settings.light, 1) : settings.lights;
  if (lights.size() > kMaxLights) {
    return invalid_argument("settings.lights", std::to_string(lights.size()),
                            "at most " + std::to_string(kMaxLights) + " lights");
  }
  const std::size_t pixels = static_cast<std::size_t>(buffers.width) * static_cast<std::size_t>(buffers.height);
  const int w = buffers.width;
  const int h = buffers.height;
  const FrameBuffers::RowPitches& pitch = buffers.row_pitch;
  SINEW_ASSIGN_OR_RETURN(const auto out_rgba8,
                         output_plane(buffers.color_rgba8, pitch.color_rgba8, 4, w, h, "buffers.color_rgba8"));
  SINEW_ASSIGN_OR_RETURN(const auto out_rgba32f,
                         output_plane(buffers.color_rgba32f, pitch.color_rgba32f, 4, w, h, "buffers.color_rgba32f"));
  SINEW_ASSIGN_OR_RETURN(const auto out_depth, output_plane(buffers.depth, pitch.depth, 1, w, h, "buffers.depth"));
  SINEW_ASSIGN_OR_RETURN(const auto out_normal, output_plane(buffers.normal, pitch.normal, 1, w, h, "buffers.normal"));
  SINEW_ASSIGN_OR_RETURN(const auto out_triangle,
                         output_plane(buffers.triangle_id, pitch.triangle_id, 1, w, h, "buffers.triangle_id"));
  SINEW_ASSIGN_OR_RETURN(const auto out_instance,
                         output_plane(buffers.instance_id, pitch.instance_id, 1, w, h, "buffers.instance_id"));

  const bool want_color = out_rgba8.wanted() || out_rgba32f.wanted();
  const bool want_surface = want_color || out_normal.wanted();
  const bool want_shadows = want_color && settings.shadows;
  const std::uint8_t all_lights = static_cast<std::uint8_t>((1u << lights.size()) - 1u);
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

    // Surfaces (shading work), then per light one shadow ray per hit that
    // faces it.
    double shadow_ns = 0.0;
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        s.lit[k] = all_lights;
        if (!s.hits[k].valid()) continue;
        ++record.hits;
        if (want_surface) s.surfaces[k] = surface_at(scene, s.hits[k], settings.default_albedo);
      }
    }
    if (want_shadows) {
      const auto shadow_start = Clock::now();
      for (std::size_t l = 0; l < lights.size(); ++l) {
        const Light& light = lights[l];
        const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
        RayPacket pending;
        std::size_t pending_pixel[kPacketSize];
        int pending_count = 0;
        const auto flush = [&] {
          if (pending_count == 0) return;
          pending.active = static_cast<std::uint8_t>((1u << pending_count) - 1u);
          const std::uint8_t blocked = occluded_packet(scene, pending, settings.triangle_test, &record.shadow);
          for (int lane = 0; lane < pending_count; ++lane) {
            if (blocked & (1u << lane)) {
              s.lit[pending_pixel[lane]] &= dark;
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
            const Vec3 to_light = light_vector(light, surface.position);
            if (glm::dot(facing, to_light) <= 0.0f) {
              s.lit[k] &= dark;  // the light is behind the surface: no ray needed
              continue;
            }
            Ray shadow;
            shadow.origin = offset_origin(surface, facing);
            shadow.direction = light_vector(light, shadow.origin);
            shadow.t_min = 0.0f;
            shadow.t_max = light.kind == Light::Kind::kPoint ? 1.0f : kInf;
            if (!settings.packets) {
              if (occluded(scene, shadow, settings.triangle_test, &record.shadow)) {
                s.lit[k] &= dark;
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
      }
      shadow_ns = nanoseconds(shadow_start, Clock::now());
    }

    // Shading and the requested outputs.
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        const Hit& hit = s.hits[k];
        if (out_triangle.wanted()) *out_triangle.at(x, y) = hit.triangle_id;
        if (out_instance.wanted()) *out_instance.at(x, y) = hit.instance_id;
        if (!hit.valid()) {
          if (out_depth.wanted()) *out_depth.at(x, y) = kInf;
          if (out_normal.wanted()) *out_normal.at(x, y) = Vec3(0.0f);
          if (out_rgba32f.wanted()) {
            float* rgba = out_rgba32f.at(x, y);
            for (int c = 0; c < 3; ++c) rgba[c] = settings.background[c];
            rgba[3] = 1.0f;
          }
          if (out_rgba8.wanted()) {
            std::uint8_t* rgba = out_rgba8.at(x, y);
            for (std::size_t c = 0; c < 4; ++c) rgba[c] = background_bytes[c];
          }
          continue;
        }
        if (out_depth.wanted()) *out_depth.at(x, y) = hit.t * glm::length(s.directions[k]);
        if (!want_surface) continue;
        const SurfacePoint& surface = s.surfaces[k];
        Vec3 facing = surface.geometric_normal;
        if (glm::dot(facing, s.directions[k]) > 0.0f) facing = -facing;
        Vec3 n = surface.shading_normal;
        if (glm::dot(n, facing) < 0.0f) n = -n;
        if (out_normal.wanted()) *out_normal.at(x, y) = n;
        if (!want_color) continue;
        Vec3 radiance = settings.ambient;
        for (std::size_t l = 0; l < lights.size(); ++l) {
          if (!(s.lit[k] & (1u << l))) continue;
          const Vec3 to_light = glm::normalize(light_vector(lights[l], surface.position));
          radiance += lights[l].color * std::max(0.0f, glm::dot(n, to_light));
        }
        const Vec3 linear = surface.albedo * radiance;
        if (out_rgba32f.wanted()) {
          float* rgba = out_rgba32f.at(x, y);
          for (int c = 0; c < 3; ++c) rgba[c] = linear[c];
          rgba[3] = 1.0f;
        }
        if (out_rgba8.wanted()) {
          std::uint8_t* rgba = out_rgba8.at(x, y);
          for (int c = 0; c < 3; ++c) rgba[c] = to_byte(linear[c]);
          rgba[3] = 255;
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
