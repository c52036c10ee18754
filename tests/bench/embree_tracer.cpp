#include "tests/bench/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "raytrace/render/stages/tile_stages.h"
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

struct TileRecord {
  std::uint64_t hits = 0;
  rt::LightRayWork light;
  double primary_ns = 0.0;
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
  std::vector<std::size_t> instance_vertex_counts;  // the caller's meshes only (their refresh checks them)
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

  Status first_build(std::span<const EmbreeMesh> meshes) {
    for (const EmbreeMesh& mesh : meshes) {
      RTCGeometry g = nullptr;
      SINEW_ASSIGN_OR_RETURN(float* vertex,
                             add_geometry(mesh.triangles, mesh.positions.size(), mesh.id, geometry_quality(), g));
      instance_geometries.push_back(g);
      instance_vertices.push_back(vertex);
      instance_vertex_counts.push_back(mesh.positions.size());
      copy_positions(mesh.positions, vertex);
      rtcCommitGeometry(g);
    }
    built = true;
    return {};
  }

  Status refresh(std::span<const EmbreeMesh> meshes) {
    if (meshes.size() != instance_geometries.size()) {
      return invalid_argument("meshes", std::to_string(meshes.size()), "changed in number since the first update");
    }
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      if (meshes[i].positions.size() != instance_vertex_counts[i]) {
        return invalid_argument("meshes[" + std::to_string(i) + "].positions",
                                std::to_string(meshes[i].positions.size()),
                                "vertex count changed since the first update");
      }
      copy_positions(meshes[i].positions, instance_vertices[i]);
      rtcUpdateGeometryBuffer(instance_geometries[i], RTC_BUFFER_TYPE_VERTEX, 0);
      rtcCommitGeometry(instance_geometries[i]);
    }
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

  // The geometry built from `source` (a scene or caller-skinned meshes) on
  // the first call, its positions refreshed on later ones; then the
  // rebuild or refit. Returns milliseconds.
  template <class Source>
  Expected<double> update(const Source& source) {
    const Clock::time_point start = Clock::now();
    if (!built) {
      SINEW_RETURN_IF_ERROR(first_build(source));
    } else {
      SINEW_RETURN_IF_ERROR(refresh(source));
    }
    rtcCommitScene(scene);
    const double ms = ms_between(start, Clock::now());
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) return embree_error(device, "rtcCommitScene");
    return ms;
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

Expected<double> EmbreeTracer::update(const rt::Scene& scene) { return state_->update(scene); }

Expected<double> EmbreeTracer::update(std::span<const EmbreeMesh> meshes) { return state_->update(meshes); }

Hit EmbreeTracer::intersect1(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
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
  rtcIntersect1(state_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return Hit{rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.primID, state_->sinew_id_of_geometry[rh.hit.geomID]};
}

namespace {

// Embree's ray packet types and calls by width.
template <class RayHitN, class RayN, auto kIntersect, auto kOccluded>
struct PacketCalls {
  using RayHit = RayHitN;
  using Ray = RayN;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { kIntersect(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { kOccluded(valid, s, c, r); }
};
template <int W>
struct Packet;
template <>
struct Packet<4> : PacketCalls<RTCRayHit4, RTCRay4, rtcIntersect4, rtcOccluded4> {};
template <>
struct Packet<8> : PacketCalls<RTCRayHit8, RTCRay8, rtcIntersect8, rtcOccluded8> {};
template <>
struct Packet<16> : PacketCalls<RTCRayHit16, RTCRay16, rtcIntersect16, rtcOccluded16> {};

// Primary rays of the tile's lanes [k, k + W) (camera origin, SoA
// directions) as one Embree packet; hits go back into the scratch.
template <int W>
void trace_primary_packet(RTCScene scene, RTCIntersectContext* context, const Vec3& eye,
                          const std::vector<std::uint32_t>& sinew_id, rt::TileScratch& s, std::size_t k) {
  alignas(64) typename Packet<W>::RayHit rh;
  alignas(64) int valid[W];
  for (int i = 0; i < W; ++i) {
    const std::size_t lane = k + static_cast<std::size_t>(i);
    valid[i] = s.is_pixel(lane) ? -1 : 0;
    rh.ray.org_x[i] = eye.x;
    rh.ray.org_y[i] = eye.y;
    rh.ray.org_z[i] = eye.z;
    rh.ray.dir_x[i] = s.dir_x[lane];
    rh.ray.dir_y[i] = s.dir_y[lane];
    rh.ray.dir_z[i] = s.dir_z[lane];
    rh.ray.tnear[i] = 0.0f;
    rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.ray.id[i] = static_cast<unsigned>(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  Packet<W>::intersect(valid, scene, context, &rh);
  for (int i = 0; i < W; ++i) {
    const std::size_t lane = k + static_cast<std::size_t>(i);
    const bool hit = valid[i] != 0 && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    s.t[lane] = hit ? rh.ray.tfar[i] : std::numeric_limits<float>::infinity();
    s.u[lane] = hit ? rh.hit.u[i] : 0.0f;
    s.v[lane] = hit ? rh.hit.v[i] : 0.0f;
    s.triangle[lane] = hit ? rh.hit.primID[i] : kInvalidId;
    s.instance[lane] = hit ? sinew_id[rh.hit.geomID[i]] : kInvalidId;
    if (hit) s.block_hits[lane / rt::kBlockLanes] |= static_cast<std::uint8_t>(1u << (lane % rt::kBlockLanes));
  }
}

// Shadow rays [i, i + W) of the scratch's compacted list as one packet;
// returns the blocked lanes as bits.
template <int W>
std::uint32_t trace_shadow_packet(RTCScene scene, RTCIntersectContext* context, const rt::TileScratch& s,
                                  std::size_t first) {
  alignas(64) typename Packet<W>::Ray r;
  alignas(64) int valid[W];
  for (int i = 0; i < W; ++i) {
    const std::size_t k = first + static_cast<std::size_t>(i);
    const bool live = k < s.shadow_count;
    valid[i] = live ? -1 : 0;
    r.org_x[i] = live ? s.so_x[k] : 0.0f;
    r.org_y[i] = live ? s.so_y[k] : 0.0f;
    r.org_z[i] = live ? s.so_z[k] : 0.0f;
    r.dir_x[i] = live ? s.sd_x[k] : 0.0f;
    r.dir_y[i] = live ? s.sd_y[k] : 0.0f;
    r.dir_z[i] = live ? s.sd_z[k] : 1.0f;
    r.tnear[i] = 0.0f;
    r.tfar[i] = live ? s.s_tmax[k] : 1.0f;
    r.time[i] = 0.0f;
    r.mask[i] = 0xFFFFFFFFu;
    r.id[i] = static_cast<unsigned>(i);
    r.flags[i] = 0;
  }
  Packet<W>::occluded(valid, scene, context, &r);
  std::uint32_t blocked = 0;
  for (int i = 0; i < W; ++i) {
    if (valid[i] != 0 && r.tfar[i] < 0.0f) blocked |= 1u << i;  // Embree sets tfar to -inf when blocked
  }
  return blocked;
}

}  // namespace

const char* embree_width_name(EmbreeWidth width) {
  switch (width) {
    case EmbreeWidth::k1: return "rtcIntersect1";
    case EmbreeWidth::k4: return "rtcIntersect4";
    case EmbreeWidth::k8: return "rtcIntersect8";
    case EmbreeWidth::k16: return "rtcIntersect16";
  }
  return "rtcIntersect";
}

Expected<EmbreeRenderStats> EmbreeTracer::render(const rt::Scene& scene, const rt::PinholeCamera& camera,
                                                 const rt::RenderSettings& settings,
                                                 std::span<std::uint8_t> color_rgba8, std::span<Hit> hits,
                                                 JobSystem& jobs, EmbreeWidth width, bool secondary_coherent) {
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
  const std::span<const rt::Light> lights =
      settings.lights.empty() ? std::span<const rt::Light>(&settings.light, 1) : settings.lights;
  const int tile = std::max(1, settings.tile_size);
  const int tiles_x = (w + tile - 1) / tile;
  const int tiles_y = (h + tile - 1) / tile;
  std::vector<TileRecord> records(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));
  rt::OutputPlanes out;
  if (!color_rgba8.empty()) out.rgba8 = {reinterpret_cast<std::byte*>(color_rgba8.data()), 4 * static_cast<std::size_t>(w), 4};
  const Vec3 eye = camera.eye();

  const Clock::time_point start = Clock::now();
  jobs.parallel_for_tiles(w, h, tile, [&](const Tile& t) {
    TileRecord& record = records[static_cast<std::size_t>(t.index)];
    rt::TileScratch& s = rt::tile_scratch();
    s.prepare(t);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    // Primary rays of one tile are coherent; shadow rays towards one point
    // light from neighbouring hits nearly so.
    if (width != EmbreeWidth::k1) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    // Area-light samples and ambient occlusion rays: whichever flag the
    // caller found faster.
    RTCIntersectContext secondary = context;
    secondary.flags = secondary_coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;

    const Clock::time_point t0 = Clock::now();
    rt::generate_camera_rays(camera, s);
    switch (width) {
      case EmbreeWidth::k1:
        for (std::size_t k = 0; k < s.lanes; ++k) {
          s.t[k] = std::numeric_limits<float>::infinity();
          s.triangle[k] = s.instance[k] = kInvalidId;
          s.u[k] = s.v[k] = 0.0f;
          if (!s.is_pixel(k)) continue;
          RTCRayHit rh;
          rh.ray.org_x = eye.x;
          rh.ray.org_y = eye.y;
          rh.ray.org_z = eye.z;
          rh.ray.dir_x = s.dir_x[k];
          rh.ray.dir_y = s.dir_y[k];
          rh.ray.dir_z = s.dir_z[k];
          rh.ray.tnear = 0.0f;
          rh.ray.tfar = std::numeric_limits<float>::infinity();
          rh.ray.time = 0.0f;
          rh.ray.mask = 0xFFFFFFFFu;
          rh.ray.id = 0;
          rh.ray.flags = 0;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(rtc_scene, &context, &rh);
          if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
          s.t[k] = rh.ray.tfar;
          s.u[k] = rh.hit.u;
          s.v[k] = rh.hit.v;
          s.triangle[k] = rh.hit.primID;
          s.instance[k] = sinew_id[rh.hit.geomID];
          s.block_hits[k / rt::kBlockLanes] |= static_cast<std::uint8_t>(1u << (k % rt::kBlockLanes));
        }
        break;
      case EmbreeWidth::k4:
        for (std::size_t k = 0; k < s.lanes; k += 4) trace_primary_packet<4>(rtc_scene, &context, eye, sinew_id, s, k);
        break;
      case EmbreeWidth::k8:
        for (std::size_t k = 0; k < s.lanes; k += 8) trace_primary_packet<8>(rtc_scene, &context, eye, sinew_id, s, k);
        break;
      case EmbreeWidth::k16:
        for (std::size_t k = 0; k < s.lanes; k += 16) {
          if (k + 16 <= s.lanes) {
            trace_primary_packet<16>(rtc_scene, &context, eye, sinew_id, s, k);
          } else {
            trace_primary_packet<8>(rtc_scene, &context, eye, sinew_id, s, k);
          }
        }
        break;
    }
    const Clock::time_point t1 = Clock::now();
    for (std::size_t b = 0; b < s.lanes / rt::kBlockLanes; ++b) {
      record.hits += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(s.block_hits[b])));
    }
    if (out.want_color()) rt::reconstruct_surfaces(scene, rt::surface_settings(settings, camera, out), s);
    // The renderer's own shadow and ambient occlusion rays, traced by
    // Embree: the same rays, the same samples.
    const auto embree_occluded = [&](int l, rt::TileScratch& rays, rt::TraversalCounters& counters) {
      rt::offset_shadow_rays(rays);
      rt::compact_shadow_rays(rays);
      counters.rays += rays.shadow_count;
      RTCIntersectContext* ray_context = rays.shadows_per_lane ? &secondary : &context;
      const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
      std::uint64_t blocked_count = 0;
      const int step = width == EmbreeWidth::k1 ? 1 : width == EmbreeWidth::k4 ? 4 : width == EmbreeWidth::k8 ? 8 : 16;
      for (std::size_t i = 0; i < rays.shadow_count; i += static_cast<std::size_t>(step)) {
        std::uint32_t blocked = 0;
        if (width == EmbreeWidth::k1) {
          RTCRay r;
          r.org_x = rays.so_x[i];
          r.org_y = rays.so_y[i];
          r.org_z = rays.so_z[i];
          r.dir_x = rays.sd_x[i];
          r.dir_y = rays.sd_y[i];
          r.dir_z = rays.sd_z[i];
          r.tnear = 0.0f;
          r.tfar = rays.s_tmax[i];
          r.time = 0.0f;
          r.mask = 0xFFFFFFFFu;
          r.id = 0;
          r.flags = 0;
          rtcOccluded1(rtc_scene, ray_context, &r);
          blocked = r.tfar < 0.0f ? 1u : 0u;
        } else if (width == EmbreeWidth::k4) {
          blocked = trace_shadow_packet<4>(rtc_scene, ray_context, rays, i);
        } else if (width == EmbreeWidth::k8) {
          blocked = trace_shadow_packet<8>(rtc_scene, ray_context, rays, i);
        } else {
          blocked = trace_shadow_packet<16>(rtc_scene, ray_context, rays, i);
        }
        for (std::uint32_t m = blocked; m != 0; m &= m - 1) {
          rays.lit[rays.shadow_pixel[i + static_cast<std::size_t>(std::countr_zero(m))]] &= dark;
          ++blocked_count;
        }
      }
      return blocked_count;
    };
    if (out.want_color()) rt::trace_light_rays(settings, lights, s, record.light, embree_occluded);
    if (out.want_color()) rt::shade_and_write(settings, lights, out, s);
    if (!hits.empty()) {
      for (std::size_t k = 0; k < s.lanes; ++k) {
        if (!s.is_pixel(k)) continue;
        const std::size_t pixel = static_cast<std::size_t>(s.pixel_y(k)) * static_cast<std::size_t>(w) +
                                  static_cast<std::size_t>(s.pixel_x(k));
        hits[pixel] = s.triangle[k] == kInvalidId ? Hit{} : Hit{s.t[k], s.u[k], s.v[k], s.triangle[k], s.instance[k]};
      }
    }
    const Clock::time_point t3 = Clock::now();
    record.primary_ns = ns_between(t0, t1);
    record.shade_ns = ns_between(t1, t3) - record.light.shadow_ns - record.light.ao_ns;
  });
  const double wall_ms = ms_between(start, Clock::now());

  EmbreeRenderStats stats;
  double primary_ns = 0.0, shadow_ns = 0.0, ao_ns = 0.0, shade_ns = 0.0;
  for (const TileRecord& r : records) {
    stats.primary_hits += r.hits;
    stats.shadow_rays += r.light.shadow.rays;
    stats.shadowed += r.light.shadowed;
    stats.ao_rays += r.light.ao.rays;
    primary_ns += r.primary_ns;
    shadow_ns += r.light.shadow_ns;
    ao_ns += r.light.ao_ns;
    shade_ns += r.shade_ns;
  }
  // As rt::Renderer: the render's wall time split in proportion to the time
  // the tiles spent in each phase.
  const double busy_ns = primary_ns + shadow_ns + ao_ns + shade_ns;
  if (busy_ns > 0.0) {
    stats.trace_primary_ms = wall_ms * primary_ns / busy_ns;
    stats.trace_shadow_ms = wall_ms * shadow_ns / busy_ns;
    stats.trace_ao_ms = wall_ms * ao_ns / busy_ns;
    stats.shade_ms = wall_ms * shade_ns / busy_ns;
  } else {
    stats.shade_ms = wall_ms;
  }
  return stats;
}

}  // namespace sinew::bench
