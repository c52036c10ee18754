#include "tests/bench/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "raytrace/render/tile_scratch.h"
#include "runtime/jobs/job_system.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

double ns_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::nano>(to - from).count();
}

Status embree_error(RTCDevice device, const char* what) {
  const RTCError code = rtcGetDeviceError(device);  // nullptr: this thread's last error
  return make_error(ErrorCode::kInternal, "embree", what, std::to_string(static_cast<int>(code)),
                    "Embree reported an error");
}

// Linear [0, 1] -> sRGB byte; the renderer's table is private to it.
class SrgbBytes {
 public:
  SrgbBytes() {
    for (std::size_t i = 0; i < bytes_.size(); ++i) {
      const double linear = static_cast<double>(i) / static_cast<double>(bytes_.size() - 1);
      const double encoded = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
      bytes_[i] = static_cast<std::uint8_t>(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
    }
  }
  std::uint8_t operator()(float linear) const {
    if (!(linear > 0.0f)) return 0;  // also NaN
    const float scaled = std::min(linear, 1.0f) * static_cast<float>(bytes_.size() - 1) + 0.5f;
    return bytes_[static_cast<std::size_t>(scaled)];
  }

 private:
  std::array<std::uint8_t, 4096> bytes_{};
};

const SrgbBytes kSrgb;

Vec3 light_vector(const rt::Light& light, const Vec3& from) {
  return light.kind == rt::Light::Kind::kPoint ? light.position - from : light.direction;
}

struct TileRecord {
  std::uint64_t hits = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t shadowed = 0;
  double primary_ns = 0.0;
  double shadow_ns = 0.0;
  double shade_ns = 0.0;
};

}  // namespace

const char* embree_mode_name(EmbreeMode mode) {
  switch (mode) {
    case EmbreeMode::kRebuildLow: return "embree rebuild LOW";
    case EmbreeMode::kRebuildMedium: return "embree rebuild MEDIUM";
    case EmbreeMode::kRefit: return "embree refit";
  }
  return "embree";
}

struct EmbreeTracer::State {
  EmbreeMode mode = EmbreeMode::kRebuildLow;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  bool built = false;
  // Per skinned instance (in scene.instances() order): its geometry and the
  // Embree-owned vertex buffer the new positions are copied into.
  std::vector<RTCGeometry> instance_geometries;
  std::vector<float*> instance_vertices;
  // Embree geometry id -> the Sinew scene's instance id reported in hits.
  std::vector<std::uint32_t> sinew_id_of_geometry;

  ~State() {
    for (RTCGeometry g : instance_geometries) rtcReleaseGeometry(g);
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  RTCBuildQuality geometry_quality() const {
    switch (mode) {
      case EmbreeMode::kRebuildLow: return RTC_BUILD_QUALITY_LOW;
      case EmbreeMode::kRebuildMedium: return RTC_BUILD_QUALITY_MEDIUM;
      case EmbreeMode::kRefit: return RTC_BUILD_QUALITY_REFIT;
    }
    return RTC_BUILD_QUALITY_LOW;
  }

  // A triangle geometry with its index buffer filled and room for `vertices`
  // positions; returns the vertex buffer.
  Expected<float*> add_geometry(std::span<const std::array<std::uint32_t, 3>> triangles, std::size_t vertices,
                                std::uint32_t sinew_id, RTCBuildQuality quality, RTCGeometry& out) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return embree_error(device, "rtcNewGeometry");
    auto* index = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangles.size()));
    auto* vertex = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
    if (!index || !vertex) {
      rtcReleaseGeometry(g);
      return embree_error(device, "rtcSetNewGeometryBuffer");
    }
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      for (std::size_t k = 0; k < 3; ++k) index[3 * t + k] = triangles[t][k];
    }
    rtcSetGeometryBuildQuality(g, quality);
    const unsigned id = rtcAttachGeometry(scene, g);
    if (sinew_id_of_geometry.size() <= id) sinew_id_of_geometry.resize(id + 1, kInvalidId);
    sinew_id_of_geometry[id] = sinew_id;
    out = g;
    return vertex;
  }

  static void copy_positions(std::span<const Vec3> positions, float* to) {
    for (std::size_t i = 0; i < positions.size(); ++i) {
      to[3 * i + 0] = positions[i].x;
      to[3 * i + 1] = positions[i].y;
      to[3 * i + 2] = positions[i].z;
    }
  }

  Status first_build(const rt::Scene& s) {
    for (const rt::InstanceFrame& frame : s.instances()) {
      const SkinnedMesh& mesh = *s.characters()[frame.character].mesh;
      RTCGeometry g = nullptr;
      SINEW_ASSIGN_OR_RETURN(float* vertex,
                             add_geometry(mesh.triangles, frame.positions.size(), frame.instance_id,
                                          geometry_quality(), g));
      instance_geometries.push_back(g);
      instance_vertices.push_back(vertex);
      copy_positions(frame.positions, vertex);
      rtcCommitGeometry(g);
    }
    for (const rt::Scene::StaticMesh& mesh : s.static_meshes()) {
      RTCGeometry g = nullptr;
      SINEW_ASSIGN_OR_RETURN(float* vertex,
                             add_geometry(mesh.desc.triangles, mesh.desc.positions.size(), mesh.instance_id,
                                          RTC_BUILD_QUALITY_MEDIUM, g));
      copy_positions(mesh.desc.positions, vertex);
      rtcCommitGeometry(g);
      rtcReleaseGeometry(g);  // the scene keeps it
    }
    built = true;
    return {};
  }

  Status refresh(const rt::Scene& s) {
    if (s.instances().size() != instance_geometries.size()) {
      return invalid_argument("scene.instances", std::to_string(s.instances().size()),
                              "changed since the first update");
    }
    for (std::size_t i = 0; i < instance_geometries.size(); ++i) {
      copy_positions(s.instances()[i].positions, instance_vertices[i]);
      rtcUpdateGeometryBuffer(instance_geometries[i], RTC_BUFFER_TYPE_VERTEX, 0);
      rtcCommitGeometry(instance_geometries[i]);
    }
    return {};
  }
};

EmbreeTracer::EmbreeTracer(std::unique_ptr<State> state) : state_(std::move(state)) {}
EmbreeTracer::~EmbreeTracer() = default;

Expected<std::unique_ptr<EmbreeTracer>> EmbreeTracer::create(EmbreeMode mode, int threads) {
  auto state = std::make_unique<State>();
  state->mode = mode;
  const std::string config = "threads=" + std::to_string(std::max(1, threads)) + ",set_affinity=0";
  state->device = rtcNewDevice(config.c_str());
  if (!state->device) return embree_error(nullptr, "rtcNewDevice");
  state->scene = rtcNewScene(state->device);
  if (!state->scene) return embree_error(state->device, "rtcNewScene");
  // Rebuilding or refitting every frame is what the dynamic flag and the
  // LOW scene quality are for; MEDIUM is Embree's default static build.
  const bool dynamic = mode != EmbreeMode::kRebuildMedium;
  rtcSetSceneFlags(state->scene, dynamic ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(state->scene, dynamic ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
  return std::unique_ptr<EmbreeTracer>(new EmbreeTracer(std::move(state)));
}

Expected<double> EmbreeTracer::update(const rt::Scene& scene) {
  State& s = *state_;
  const Clock::time_point start = Clock::now();
  if (!s.built) {
    SINEW_RETURN_IF_ERROR(s.first_build(scene));
  } else {
    SINEW_RETURN_IF_ERROR(s.refresh(scene));
  }
  rtcCommitScene(s.scene);
  const double ms = ms_between(start, Clock::now());
  if (rtcGetDeviceError(s.device) != RTC_ERROR_NONE) return embree_error(s.device, "rtcCommitScene");
  return ms;
}

Expected<EmbreeRenderStats> EmbreeTracer::render(const rt::Scene& scene, const rt::PinholeCamera& camera,
                                                 const rt::RenderSettings& settings,
                                                 std::span<std::uint8_t> color_rgba8, std::span<Hit> hits,
                                                 JobSystem& jobs) {
  const int w = camera.width();
  const int h = camera.height();
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (!color_rgba8.empty() && color_rgba8.size() != 4 * pixels) {
    return invalid_argument("color_rgba8", std::to_string(color_rgba8.size()), "is not width x height x 4");
  }
  if (!hits.empty() && hits.size() != pixels) {
    return invalid_argument("hits", std::to_string(hits.size()), "is not width x height");
  }
  if (!state_->built) return invalid_argument("embree scene", "not built", "call update first");
  const RTCScene rtc_scene = state_->scene;
  const std::vector<std::uint32_t>& sinew_id = state_->sinew_id_of_geometry;
  const rt::Light& light = settings.light;
  const bool shadows = settings.shadows;
  const int tile = std::max(1, settings.tile_size);
  const int tiles_x = (w + tile - 1) / tile;
  const int tiles_y = (h + tile - 1) / tile;
  std::vector<TileRecord> records(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));
  const std::array<std::uint8_t, 4> background = {kSrgb(settings.background.x), kSrgb(settings.background.y),
                                                   kSrgb(settings.background.z), 255};

  const Clock::time_point start = Clock::now();
  jobs.parallel_for_tiles(w, h, tile, [&](const Tile& t) {
    TileRecord& record = records[static_cast<std::size_t>(t.index)];
    const int tw = t.x1 - t.x0;
    const auto local = [&](int x, int y) { return static_cast<std::size_t>((y - t.y0) * tw + (x - t.x0)); };
    rt::TileScratch& s = rt::tile_scratch();
    s.resize(static_cast<std::size_t>(tw * (t.y1 - t.y0)));
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);

    const Clock::time_point t0 = Clock::now();
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const Ray ray = camera.ray(x, y);
        RTCRayHit rh;
        rh.ray.org_x = ray.origin.x;
        rh.ray.org_y = ray.origin.y;
        rh.ray.org_z = ray.origin.z;
        rh.ray.dir_x = ray.direction.x;
        rh.ray.dir_y = ray.direction.y;
        rh.ray.dir_z = ray.direction.z;
        rh.ray.tnear = ray.t_min;
        rh.ray.tfar = ray.t_max;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context, &rh);
        const std::size_t k = local(x, y);
        s.directions[k] = ray.direction;
        s.hits[k] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                        ? Hit{}
                        : Hit{rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.primID, sinew_id[rh.hit.geomID]};
      }
    }
    const Clock::time_point t1 = Clock::now();

    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        s.lit[k] = 1;
        if (!s.hits[k].valid()) continue;
        ++record.hits;
        s.surfaces[k] = rt::surface_at(scene, s.hits[k], settings.default_albedo);
      }
    }
    double shadow_ns = 0.0;
    if (shadows) {
      const Clock::time_point shadow_start = Clock::now();
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          const std::size_t k = local(x, y);
          if (!s.hits[k].valid()) continue;
          const rt::SurfacePoint& surface = s.surfaces[k];
          Vec3 facing = surface.geometric_normal;
          if (glm::dot(facing, s.directions[k]) > 0.0f) facing = -facing;
          if (glm::dot(facing, light_vector(light, surface.position)) <= 0.0f) {
            s.lit[k] = 0;  // the light is behind the surface: no ray needed
            continue;
          }
          const Vec3 origin = rt::offset_origin(surface, facing);
          const Vec3 direction = light_vector(light, origin);
          RTCRay shadow;
          shadow.org_x = origin.x;
          shadow.org_y = origin.y;
          shadow.org_z = origin.z;
          shadow.dir_x = direction.x;
          shadow.dir_y = direction.y;
          shadow.dir_z = direction.z;
          shadow.tnear = 0.0f;
          shadow.tfar = light.kind == rt::Light::Kind::kPoint ? 1.0f : std::numeric_limits<float>::infinity();
          shadow.time = 0.0f;
          shadow.mask = 0xFFFFFFFFu;
          shadow.id = 0;
          shadow.flags = 0;
          rtcOccluded1(rtc_scene, &context, &shadow);
          ++record.shadow_rays;
          if (shadow.tfar < 0.0f) {  // Embree sets tfar to -inf when blocked
            s.lit[k] = 0;
            ++record.shadowed;
          }
        }
      }
      shadow_ns = ns_between(shadow_start, Clock::now());
    }

    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t k = local(x, y);
        const Hit& hit = s.hits[k];
        const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                                  static_cast<std::size_t>(x);
        if (!hits.empty()) hits[pixel] = hit;
        if (color_rgba8.empty()) continue;
        std::uint8_t* rgba = color_rgba8.data() + 4 * pixel;
        if (!hit.valid()) {
          std::memcpy(rgba, background.data(), 4);
          continue;
        }
        const rt::SurfacePoint& surface = s.surfaces[k];
        Vec3 facing = surface.geometric_normal;
        if (glm::dot(facing, s.directions[k]) > 0.0f) facing = -facing;
        Vec3 n = surface.shading_normal;
        if (glm::dot(n, facing) < 0.0f) n = -n;
        Vec3 radiance = settings.ambient;
        if (s.lit[k]) {
          const Vec3 to_light = glm::normalize(light_vector(light, surface.position));
          radiance += light.color * std::max(0.0f, glm::dot(n, to_light));
        }
        const Vec3 linear = surface.albedo * radiance;
        for (int c = 0; c < 3; ++c) rgba[c] = kSrgb(linear[c]);
        rgba[3] = 255;
      }
    }
    const Clock::time_point t3 = Clock::now();
    record.primary_ns = ns_between(t0, t1);
    record.shadow_ns = shadow_ns;
    record.shade_ns = ns_between(t1, t3) - shadow_ns;
  });
  const double wall_ms = ms_between(start, Clock::now());

  EmbreeRenderStats stats;
  double primary_ns = 0.0, shadow_ns = 0.0, shade_ns = 0.0;
  for (const TileRecord& r : records) {
    stats.primary_hits += r.hits;
    stats.shadow_rays += r.shadow_rays;
    stats.shadowed += r.shadowed;
    primary_ns += r.primary_ns;
    shadow_ns += r.shadow_ns;
    shade_ns += r.shade_ns;
  }
  // As rt::Renderer: the render's wall time split in proportion to the time
  // the tiles spent in each phase.
  const double busy_ns = primary_ns + shadow_ns + shade_ns;
  if (busy_ns > 0.0) {
    stats.trace_primary_ms = wall_ms * primary_ns / busy_ns;
    stats.trace_shadow_ms = wall_ms * shadow_ns / busy_ns;
    stats.shade_ms = wall_ms * shade_ns / busy_ns;
  } else {
    stats.shade_ms = wall_ms;
  }
  return stats;
}

}  // namespace sinew::bench
