// host_engine: the smallest "engine frame" that embeds Sinew as one pass.
//
// The host owns the camera, the light and a rasterised pass of its own (sky
// and ground). Each frame it animates Sinew's world, runs Sinew's ray-trace
// pass into host-owned colour and depth buffers, rasterises its ground into
// a G-buffer, asks a second Sinew pass (the G-buffer mode) how much of the
// light reaches each of its ground's pixels past the characters, shades
// the ground with that shadow mask, and composites the two passes by
// depth. The light is a sphere light: both the characters and the
// characters' shadows on the ground are soft. Everything Sinew-specific
// goes through <sinew/sinew.h>.
//
//   host_engine --pack cesium.pack --headless --out frames/
//   host_engine --pack cesium.pack --scheduler host --threads 4   (a window)
//
// It also asks the world questions between passes, as a game does: a click
// (or --pick) casts the camera ray through a pixel to select a character,
// and each printed frame a line-of-sight test casts one ray from the light
// toward every character.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <sinew/sinew.h>

#include "host_raster.h"
#include "image_files.h"
#include "thread_pool.h"

#if HOST_ENGINE_WINDOW
#include <GLFW/glfw3.h>
#endif

namespace api = sinew::api;

namespace {

constexpr int kExitSinewError = 1;
constexpr int kExitUsage = 2;
constexpr float kFrameStep = 1.0f / 30.0f;
constexpr float kInstanceSpacing = 1.0f;  // instance i stands i units along +X

// --- options ---------------------------------------------------------------

struct Pixel {
  int x = 0;
  int y = 0;  // 0: the top row, as in the pass's images
};

struct Options {
  std::string pack;
  std::string clip = "#0";
  double time = 0.0;
  int width = 640;
  int height = 480;
  std::optional<api::Camera> camera;
  std::optional<api::Float3> light;
  std::optional<float> light_radius;
  int shadow_samples = 8;
  int instances = 1;
  int frames = 0;  // 0: one frame posed with pose_at; N: N frames of advance()
  int threads = 0;
  bool host_scheduler = false;
  bool headless = false;
  std::string out = ".";
  std::optional<Pixel> pick;
};

const char* const kUsage =
    "usage: host_engine --pack PACK [options]\n"
    "  --pack PACK            a baked character pack (sinew-editor bake)\n"
    "  --clip NAME|#I         the clip (default #0)\n"
    "  --time SECONDS         the clip time of the first frame (default 0)\n"
    "  --size WxH             image size (default 640x480)\n"
    "  --camera ex,ey,ez,tx,ty,tz,ux,uy,uz,fovy_deg\n"
    "                         default: frames the character's bind-pose skeleton\n"
    "  --light x,y,z          the light's centre (default: above, in front, to the right)\n"
    "  --light-radius R       the sphere light's radius, scene units (0: a point light with hard\n"
    "                         shadows; default: a tenth of the character's height)\n"
    "  --shadow-samples N     shadow rays per pixel towards the sphere light (default 8)\n"
    "  --instances N          copies 1 unit apart along +X (default 1)\n"
    "  --frames N             animate N frames at 30 fps with World::advance (headless: write\n"
    "                         the last; windowed: close after N). Default headless: one frame\n"
    "                         posed with World::pose_at; windowed: run until Esc\n"
    "  --threads N            worker threads (default 0: all cores)\n"
    "  --scheduler tbb|host   Sinew's own TBB arena, or the host's thread pool (default tbb)\n"
    "  --headless             no window: write OUT/sinew_color.ppm, sinew_depth.pfm,\n"
    "                         ground_shadow.pfm (the host ground's shadow mask), frame.ppm\n"
    "  --out DIR              output folder of --headless (default .)\n"
    "  --pick X,Y             select the character under pixel X,Y (0,0 the top left) before the\n"
    "                         written (windowed: the first) frame; frame.ppm shows it tinted\n"
    "                         orange (sinew_color.ppm stays Sinew's own). Windowed, a left click\n"
    "                         selects too; a click on nothing clears the selection\n"
    "Each printed frame also reports a line-of-sight test: one ray from the light toward each\n"
    "instance's middle, and whether it reaches that instance or another one is in the way.\n"
    "Exit status: 0 success, 1 a Sinew (or file) error, 2 bad usage.\n";

bool parse_number(std::string_view text, float& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && std::isfinite(value);
}

bool parse_number(std::string_view text, int& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

std::optional<std::vector<float>> parse_floats(std::string_view text, std::size_t count) {
  std::vector<float> values;
  for (;;) {
    const std::size_t comma = text.find(',');
    float v = 0.0f;
    if (!parse_number(text.substr(0, comma), v)) return std::nullopt;
    values.push_back(v);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  if (values.size() != count) return std::nullopt;
  return values;
}

// "X,Y"; checked against the image size once --size is known.
std::optional<Pixel> parse_pixel(std::string_view text) {
  const std::size_t comma = text.find(',');
  Pixel p;
  if (comma == std::string_view::npos || !parse_number(text.substr(0, comma), p.x) ||
      !parse_number(text.substr(comma + 1), p.y)) {
    return std::nullopt;
  }
  return p;
}

// Returns the error that makes the command line unusable, or "".
std::string parse_options(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (flag == "--help") return "help";
    if (flag == "--headless") {
      o.headless = true;
      continue;
    }
    if (i + 1 >= argc) return std::string(flag) + " needs a value (or is unknown)";
    const std::string_view value = argv[++i];
    const std::string bad = "bad value for " + std::string(flag) + ": '" + std::string(value) + "'";
    if (flag == "--pack") {
      o.pack = value;
    } else if (flag == "--clip") {
      o.clip = value;
    } else if (flag == "--time") {
      float t = 0.0f;
      if (!parse_number(value, t) || t < 0.0f) return bad;
      o.time = t;
    } else if (flag == "--size") {
      const std::size_t x = value.find('x');
      if (x == std::string_view::npos || !parse_number(value.substr(0, x), o.width) ||
          !parse_number(value.substr(x + 1), o.height) || o.width < 1 || o.height < 1) {
        return bad;
      }
    } else if (flag == "--camera") {
      const auto v = parse_floats(value, 10);
      if (!v) return bad;
      const auto& f = *v;
      o.camera = api::Camera{{f[0], f[1], f[2]}, {f[3], f[4], f[5]}, {f[6], f[7], f[8]}, f[9]};
    } else if (flag == "--light") {
      const auto v = parse_floats(value, 3);
      if (!v) return bad;
      o.light = api::Float3{(*v)[0], (*v)[1], (*v)[2]};
    } else if (flag == "--light-radius") {
      float r = 0.0f;
      if (!parse_number(value, r) || r < 0.0f) return bad;
      o.light_radius = r;
    } else if (flag == "--shadow-samples") {
      if (!parse_number(value, o.shadow_samples) || o.shadow_samples < 1 || o.shadow_samples > 256) return bad;
    } else if (flag == "--instances") {
      if (!parse_number(value, o.instances) || o.instances < 1) return bad;
    } else if (flag == "--frames") {
      if (!parse_number(value, o.frames) || o.frames < 1) return bad;
    } else if (flag == "--threads") {
      if (!parse_number(value, o.threads) || o.threads < 0) return bad;
    } else if (flag == "--scheduler") {
      if (value != "tbb" && value != "host") return bad;
      o.host_scheduler = value == "host";
    } else if (flag == "--out") {
      o.out = value;
    } else if (flag == "--pick") {
      o.pick = parse_pixel(value);
      if (!o.pick) return bad;
    } else {
      return "unknown option " + std::string(flag);
    }
  }
  if (o.pack.empty()) return "--pack is required";
  if (o.pick && (o.pick->x < 0 || o.pick->x >= o.width || o.pick->y < 0 || o.pick->y >= o.height)) {
    return "--pick " + std::to_string(o.pick->x) + "," + std::to_string(o.pick->y) + " lies outside the " +
           std::to_string(o.width) + "x" + std::to_string(o.height) + " image";
  }
  return "";
}

// --- framing the character -------------------------------------------------

// Where the characters stand, for the default camera, light and ground.
struct Framing {
  int up_axis = 1;  // 1: Y-up, 2: Z-up (the larger extent, as sinew-editor decides)
  host::Vec3 low;
  host::Vec3 high;
};

float& axis(host::Vec3& v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }
float axis(const host::Vec3& v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

// The API gives no mesh bounds, and a mixer-driven instance need not stand
// in the space of Character::bind_pose (a glTF scene's Z-up root node, say).
// So measure what Sinew actually renders: a small depth-only pass over the
// world, from two sides, turns each hit back into a point (eye + depth * ray),
// since depth is the distance along the unit ray. It also shows that a host
// may own several passes with different outputs over one World.
api::Result<Framing> measure_world(api::World& world, const api::Character& character, int instances) {
  // A generous guess at a sphere holding the instances: twice the
  // skeleton's reach from the origin (whatever rotation the mixer's root
  // applies keeps that distance), plus the row along +X. What falls outside
  // it is only missing from the bounds, which then frame the rest.
  float reach = 0.5f;
  for (std::size_t bone = 0; bone < character.bone_count(); ++bone) {
    const api::Matrix3x4 m = character.bind_pose(bone);
    reach = std::max(reach, std::sqrt(m.m[0][3] * m.m[0][3] + m.m[1][3] * m.m[1][3] + m.m[2][3] * m.m[2][3]));
  }
  const float row = kInstanceSpacing * static_cast<float>(instances - 1);
  const api::Float3 centre{0.5f * row, 0.0f, 0.0f};
  const float radius = 2.0f * reach + 0.5f * row;

  constexpr int kProbeSize = 160;
  constexpr float kProbeFovy = 40.0f;
  api::PassDesc desc;
  desc.width = kProbeSize;
  desc.height = kProbeSize;
  desc.outputs = static_cast<api::OutputMask>(api::Output::kDepth);
  auto probe = api::RayTracePass::create(desc);
  if (!probe) return probe.error();

  const float inf = host::kFarAway;
  Framing f;
  f.low = {inf, inf, inf};
  f.high = {-inf, -inf, -inf};
  const float distance = radius / std::sin(0.5f * kProbeFovy * 3.14159265f / 180.0f);
  for (const api::Float3 side : {api::Float3{0, 0, 1}, api::Float3{1, 0, 0}}) {
    api::PassInputs inputs;
    inputs.camera = {{centre.x + distance * side.x, centre.y, centre.z + distance * side.z}, centre, {0, 1, 0},
                     kProbeFovy};
    host::Image depth(kProbeSize, kProbeSize, sizeof(float));
    api::PassOutputs outputs;
    outputs.depth = depth.as_output();
    if (auto stats = probe->execute(world, inputs, outputs); !stats) return stats.error();
    const host::PinholeCamera camera = host::PinholeCamera::from(inputs.camera, kProbeSize, kProbeSize);
    for (int y = 0; y < kProbeSize; ++y) {
      for (int x = 0; x < kProbeSize; ++x) {
        const float d = depth.row<float>(y)[x];
        if (d == inf) continue;
        const host::Vec3 ray = camera.ray_direction(x, y);
        const host::Vec3 p{camera.eye.x + d * ray.x, camera.eye.y + d * ray.y, camera.eye.z + d * ray.z};
        for (int a = 0; a < 3; ++a) {
          axis(f.low, a) = std::min(axis(f.low, a), axis(p, a));
          axis(f.high, a) = std::max(axis(f.high, a), axis(p, a));
        }
      }
    }
  }
  if (f.low.x == inf) {
    // Nothing seen (an empty mesh): assume a Y-up human 1.8 units tall.
    f.low = {-0.5f, 0.0f, -0.5f};
    f.high = {0.5f + row, 1.8f, 0.5f};
  }
  f.up_axis = f.high.y - f.low.y >= f.high.z - f.low.z ? 1 : 2;
  return f;
}

host::Vec3 center_of(const Framing& f) {
  return {0.5f * (f.low.x + f.high.x), 0.5f * (f.low.y + f.high.y), 0.5f * (f.low.z + f.high.z)};
}

float radius_of(const Framing& f) {
  const host::Vec3 e{f.high.x - f.low.x, f.high.y - f.low.y, f.high.z - f.low.z};
  return 0.5f * std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
}

// The character's front, as sinew-editor render looks at it: from +Z for a
// Y-up model, from -Y for a Z-up one.
host::Vec3 front_of(int up_axis) { return up_axis == 1 ? host::Vec3{0, 0, 1} : host::Vec3{0, -1, 0}; }

api::Camera default_camera(const Framing& f, int width, int height) {
  constexpr float kFovyDegrees = 40.0f;
  const float half_fovy = 0.5f * kFovyDegrees * 3.14159265f / 180.0f;
  const float half_fovx = std::atan(std::tan(half_fovy) * static_cast<float>(width) / static_cast<float>(height));
  const float distance = 1.15f * radius_of(f) / std::sin(std::min(half_fovy, half_fovx));
  host::Vec3 up;
  axis(up, f.up_axis) = 1.0f;
  const host::Vec3 front = front_of(f.up_axis);
  const host::Vec3 c = center_of(f);
  const host::Vec3 view{front.x + 0.2f * up.x, front.y + 0.2f * up.y, front.z + 0.2f * up.z};
  const float s = distance / std::sqrt(view.x * view.x + view.y * view.y + view.z * view.z);
  return {{c.x + s * view.x, c.y + s * view.y, c.z + s * view.z}, {c.x, c.y, c.z}, {up.x, up.y, up.z}, kFovyDegrees};
}

api::Float3 default_light(const Framing& f) {
  const float r = radius_of(f);
  const host::Vec3 c = center_of(f);
  const host::Vec3 front = front_of(f.up_axis);
  host::Vec3 up;
  axis(up, f.up_axis) = 1.0f;
  return {c.x + r * (2.0f * front.x + 3.0f * up.x + 1.0f), c.y + r * (2.0f * front.y + 3.0f * up.y),
          c.z + r * (2.0f * front.z + 3.0f * up.z)};
}

// The ground lies under the lowest point of the measured bind pose, where
// the character's feet are; the host's quad is big enough to reach the
// horizon of the default camera, its squares a third of the character's
// height (packs come in metres, centimetres, inches...).
host::Ground ground_under(const Framing& f) {
  host::Ground g;
  g.up_axis = f.up_axis;
  g.height = axis(f.low, f.up_axis);
  g.center = center_of(f);
  g.half_size = 10.0f * radius_of(f);
  g.checker_size = std::max(1e-3f, (axis(f.high, f.up_axis) - axis(f.low, f.up_axis)) / 3.0f);
  return g;
}

// --- the engine --------------------------------------------------------------

struct Frame {
  explicit Frame(int w, int h)
      : sinew_color(w, h, 4),
        sinew_depth(w, h, sizeof(float)),
        sinew_instance(w, h, sizeof(api::InstanceId)),
        gbuffer(w, h),
        ground_shadow(w, h, sizeof(float)),
        host_color(w, h, 4) {}
  host::Image sinew_color;
  host::Image sinew_depth;
  host::Image sinew_instance;  // which instance each pixel shows: the selection's highlight
  host::GBuffer gbuffer;       // the host's rasterised ground; its depth is the composite's too
  host::Image ground_shadow;   // Sinew's shadow mask of the host's G-buffer
  host::Image host_color;      // after composite_by_depth: the finished frame
};

struct Engine {
  api::Character character;
  api::World world;
  api::RayTracePass pass;
  api::RayTracePass shadow_pass;  // the G-buffer mode: the host ground's shadow mask
  std::vector<api::InstanceId> instances;
  api::Light light;
  api::PassInputs inputs;
  std::unique_ptr<host::ThreadPool> pool;  // --scheduler host only
  api::TaskScheduler scheduler;
  host::PinholeCamera camera;
  host::Ground ground;
  host::HostLighting lighting;
  Frame frame;
  Framing framing;  // where the line-of-sight test aims
  api::InstanceId selection = api::kNoHit;  // picked by a click or --pick
};

struct FrameStats {
  api::PassStats sinew;
  api::PassStats ground_shadow;
  double host_ms = 0.0;
  double composite_ms = 0.0;
};

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// One frame: Sinew's pass, the host's pass (its G-buffer, Sinew's shadow
// mask of it, its shading), then the composite. Sinew goes first only
// because it validates the camera the passes share (a real engine would
// run the character pass beside its own: they share no buffer until the
// composite).
api::Result<FrameStats> render_frame(Engine& e) {
  FrameStats stats;
  const api::TaskScheduler* scheduler = e.pool ? &e.scheduler : nullptr;
  api::PassOutputs outputs;
  outputs.color_rgba8 = e.frame.sinew_color.as_output();
  outputs.depth = e.frame.sinew_depth.as_output();
  outputs.instance_id = e.frame.sinew_instance.as_output();
  auto sinew = e.pass.execute(e.world, e.inputs, outputs, scheduler);
  if (!sinew) return sinew.error();
  stats.sinew = *sinew;

  auto start = std::chrono::steady_clock::now();
  host::GBuffer& gbuffer = e.frame.gbuffer;
  host::draw_host_gbuffer(e.camera, e.ground, gbuffer);
  stats.host_ms = ms_since(start);

  // The host's surfaces as the rays' origins: Sinew's characters shadow
  // the host's ground, which Sinew's World does not hold.
  api::PassInputs shadow_inputs = e.inputs;
  shadow_inputs.gbuffer.position = {gbuffer.position.data(), gbuffer.position.row_pitch()};
  shadow_inputs.gbuffer.normal = {gbuffer.normal.data(), gbuffer.normal.row_pitch()};
  api::PassOutputs shadow_outputs;
  shadow_outputs.shadow_mask = e.frame.ground_shadow.as_output();
  auto shadow = e.shadow_pass.execute(e.world, shadow_inputs, shadow_outputs, scheduler);
  if (!shadow) return shadow.error();
  stats.ground_shadow = *shadow;

  start = std::chrono::steady_clock::now();
  host::shade_host_pass(e.camera, e.ground, e.lighting, gbuffer, e.frame.ground_shadow, e.frame.host_color);
  stats.host_ms += ms_since(start);

  start = std::chrono::steady_clock::now();
  host::composite_by_depth(e.frame.sinew_color, e.frame.sinew_depth, e.frame.host_color, gbuffer.depth);
  if (e.selection != api::kNoHit) {
    host::highlight_instance(e.frame.sinew_instance, e.frame.sinew_depth, e.selection, e.frame.host_color,
                             gbuffer.depth);
  }
  stats.composite_ms = ms_since(start);
  return stats;
}

void print_stats(int frame, const FrameStats& s) {
  std::printf(
      "frame %d: sinew prepare %.2f ms, trace %.2f ms, shade %.2f ms, %zu escaped triangles | ground shadow "
      "prepare %.2f ms, trace %.2f ms | host raster %.2f ms, composite %.2f ms\n",
      frame, s.sinew.prepare_ms, s.sinew.trace_ms, s.sinew.shade_ms, s.sinew.escaped_triangles,
      s.ground_shadow.prepare_ms, s.ground_shadow.trace_ms, s.host_ms, s.composite_ms);
  std::fflush(stdout);
}

int sinew_failed(const api::Error& error) {
  std::fprintf(stderr, "host_engine: sinew: %s\n", error.message.c_str());
  return kExitSinewError;
}

// --- queries between passes ------------------------------------------------

// The camera ray through the pixel's centre, the ray the pass traced for
// it: what it meets first is what the pixel shows. The world must still be
// posed as in the frame the user sees (query before the next advance).
api::Status pick(Engine& e, Pixel pixel) {
  const host::Vec3 direction = e.camera.ray_direction(pixel.x, pixel.y);
  api::Ray ray;
  ray.origin = e.inputs.camera.eye;
  ray.direction = {direction.x, direction.y, direction.z};
  auto hit = e.world.intersect(ray);
  if (!hit) return hit.error();
  e.selection = hit->instance;  // kNoHit on a miss: the selection is cleared
  if (hit->hit()) {
    std::printf("pick %d,%d: selected instance %u, triangle %u, %.3f from the eye\n", pixel.x, pixel.y,
                static_cast<unsigned>(hit->instance), static_cast<unsigned>(hit->triangle),
                static_cast<double>(hit->t));  // the direction is unit: t is the distance
  } else {
    std::printf("pick %d,%d: nothing there, selection cleared\n", pixel.x, pixel.y);
  }
  std::fflush(stdout);
  return {};
}

// A gameplay ray test: can the light see each character? One segment per
// instance, from the light to the middle of where it stands (the bind-pose
// framing: instance i stands kInstanceSpacing * i along +X of the first).
// Only another instance or a static mesh on the segment hides it: reaching
// the middle without meeting its own surface (a gap in its pose) still
// counts as seen.
api::Result<std::string> line_of_sight(Engine& e) {
  const host::Vec3 middle = center_of(e.framing);
  const float row = kInstanceSpacing * static_cast<float>(e.instances.size() - 1);
  const api::Float3 from = e.light.position;
  std::vector<api::Ray> rays(e.instances.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const float x = middle.x - 0.5f * row + kInstanceSpacing * static_cast<float>(i);
    rays[i].origin = from;
    rays[i].direction = {x - from.x, middle.y - from.y, middle.z - from.z};
    rays[i].t_max = 1.0f;  // the segment ends at the middle: nothing behind it counts
  }
  std::vector<api::RayHit> hits(rays.size());
  if (auto s = e.world.intersect(rays, hits); !s) return s.error();

  std::string report = "line of sight from the light:";
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const api::InstanceId blocker = hits[i].instance;
    report += (i == 0 ? " instance " : ", instance ") + std::to_string(e.instances[i]);
    if (blocker == api::kNoHit || blocker == e.instances[i]) {
      report += " visible";
    } else if (std::find(e.instances.begin(), e.instances.end(), blocker) != e.instances.end()) {
      report += " hidden behind instance " + std::to_string(blocker);
    } else {
      report += " blocked by static mesh " + std::to_string(blocker);
    }
  }
  return report;
}

// The stats line, then the line-of-sight test on the frame just rendered
// (the world is posed as the pass saw it, so the query reuses its work).
api::Status report_frame(Engine& e, int frame, const FrameStats& stats) {
  print_stats(frame, stats);
  auto sight = line_of_sight(e);
  if (!sight) return sight.error();
  std::printf("frame %d: %s\n", frame, sight->c_str());
  std::fflush(stdout);
  return {};
}

// Every instance plays the clip through the mixer, so World::advance moves
// them all at once.
api::Status start_playing(Engine& e, const Options& o) {
  for (const api::InstanceId id : e.instances) {
    if (auto s = e.world.play_cycle(id, o.clip, 1.0f, 0.0f); !s) return s;
  }
  // play_cycle started the clock: jump to --time.
  return e.world.advance(static_cast<float>(o.time));
}

// How much of the host's ground the characters shadow, from Sinew's mask:
// pixels the light reaches only in part (below 1), and of those the
// penumbra (above 0), where a sphere light's shadow is soft.
void report_ground_shadow(const host::Image& shadow) {
  std::size_t shadowed = 0;
  std::size_t penumbra = 0;
  for (int y = 0; y < shadow.height(); ++y) {
    const float* row = shadow.row<float>(y);
    for (int x = 0; x < shadow.width(); ++x) {
      shadowed += row[x] < 1.0f ? 1 : 0;
      penumbra += row[x] > 0.0f && row[x] < 1.0f ? 1 : 0;
    }
  }
  std::printf("ground shadow: %zu pixels shadowed, %zu of them in penumbra\n", shadowed, penumbra);
}

int run_headless(Engine& e, const Options& o) {
  if (o.frames == 0) {
    for (const api::InstanceId id : e.instances) {
      if (auto s = e.world.pose_at(id, o.clip, o.time); !s) return sinew_failed(s.error());
    }
  } else {
    if (auto s = start_playing(e, o); !s) return sinew_failed(s.error());
  }
  const int frames = std::max(o.frames, 1);
  for (int f = 0; f < frames; ++f) {
    if (f > 0) {
      if (auto s = e.world.advance(kFrameStep); !s) return sinew_failed(s.error());
    }
    // Picked on the pose about to be rendered: the frame written is the one picked in.
    if (o.pick && f == frames - 1) {
      if (auto s = pick(e, *o.pick); !s) return sinew_failed(s.error());
    }
    auto stats = render_frame(e);
    if (!stats) return sinew_failed(stats.error());
    if (auto s = report_frame(e, f, *stats); !s) return sinew_failed(s.error());
  }
  report_ground_shadow(e.frame.ground_shadow);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  const std::filesystem::path dir(o.out);
  if (!host::write_ppm((dir / "sinew_color.ppm").string(), e.frame.sinew_color) ||
      !host::write_pfm((dir / "sinew_depth.pfm").string(), e.frame.sinew_depth) ||
      !host::write_pfm((dir / "ground_shadow.pfm").string(), e.frame.ground_shadow) ||
      !host::write_ppm((dir / "frame.ppm").string(), e.frame.host_color)) {
    std::fprintf(stderr, "host_engine: cannot write the images into %s\n", o.out.c_str());
    return kExitSinewError;
  }
  std::printf("wrote %s/{sinew_color.ppm,sinew_depth.pfm,ground_shadow.pfm,frame.ppm}\n", o.out.c_str());
  return 0;
}

#if HOST_ENGINE_WINDOW
// A left click waits here, in window coordinates, until the loop is between
// passes: the callback runs inside glfwPollEvents.
struct PendingClick {
  bool pending = false;
  double x = 0.0;
  double y = 0.0;
};

void on_mouse_button(GLFWwindow* window, int button, int action, int /*mods*/) {
  if (button != GLFW_MOUSE_BUTTON_LEFT || action != GLFW_PRESS) return;
  auto* click = static_cast<PendingClick*>(glfwGetWindowUserPointer(window));
  glfwGetCursorPos(window, &click->x, &click->y);
  click->pending = true;
}

// Window coordinates (screen units, which HiDPI scaling or a window manager
// may make differ from the image's pixels) to the image pixel under them.
std::optional<Pixel> image_pixel(GLFWwindow* window, const PendingClick& click, int width, int height) {
  int window_width = 0;
  int window_height = 0;
  glfwGetWindowSize(window, &window_width, &window_height);
  if (window_width <= 0 || window_height <= 0) return std::nullopt;
  const double x = std::floor(click.x * width / window_width);
  const double y = std::floor(click.y * height / window_height);
  if (x < 0.0 || x >= width || y < 0.0 || y >= height) return std::nullopt;
  return Pixel{static_cast<int>(x), static_cast<int>(y)};
}

int run_windowed(Engine& e, const Options& o) {
  if (glfwInit() == GLFW_FALSE) {
    std::fprintf(stderr, "host_engine: no display (GLFW failed to start): use --headless\n");
    return kExitSinewError;
  }
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, "Sinew host engine", nullptr, nullptr);
  if (window == nullptr) {
    glfwTerminate();
    std::fprintf(stderr, "host_engine: cannot open a %dx%d OpenGL window\n", o.width, o.height);
    return kExitSinewError;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  PendingClick click;
  glfwSetWindowUserPointer(window, &click);
  glfwSetMouseButtonCallback(window, on_mouse_button);

  int status = 0;
  std::vector<std::uint8_t> bottom_up(static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height) * 4);
  if (auto s = start_playing(e, o); !s) status = sinew_failed(s.error());
  double last = glfwGetTime();
  for (int f = 0; status == 0 && !glfwWindowShouldClose(window) && (o.frames == 0 || f < o.frames); ++f) {
    glfwPollEvents();
    if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
    // Before advance: the world is still posed as in the frame clicked on.
    std::optional<Pixel> picked = f == 0 ? o.pick : std::nullopt;
    if (click.pending) {
      click.pending = false;
      picked = image_pixel(window, click, o.width, o.height);
    }
    if (picked) {
      if (auto s = pick(e, *picked); !s) {
        status = sinew_failed(s.error());
        break;
      }
    }
    // Real time, but never a jump of more than a few frames (a stall, a
    // debugger): the clip keeps cycling smoothly.
    const double now = glfwGetTime();
    const float dt = f == 0 ? 0.0f : static_cast<float>(std::min(now - last, 0.1));
    last = now;
    if (auto s = e.world.advance(dt); !s) {
      status = sinew_failed(s.error());
      break;
    }
    auto stats = render_frame(e);
    if (!stats) {
      status = sinew_failed(stats.error());
      break;
    }
    if (o.frames != 0 || f % 30 == 0) {
      if (auto s = report_frame(e, f, *stats); !s) {
        status = sinew_failed(s.error());
        break;
      }
    }

    // glDrawPixels wants rows bottom to top; Sinew and the host write top down.
    const std::size_t row_bytes = static_cast<std::size_t>(o.width) * 4;
    for (int y = 0; y < o.height; ++y) {
      std::copy_n(e.frame.host_color.row<std::uint8_t>(y), row_bytes,
                  bottom_up.data() + static_cast<std::size_t>(o.height - 1 - y) * row_bytes);
    }
    int fb_width = 0;
    int fb_height = 0;
    glfwGetFramebufferSize(window, &fb_width, &fb_height);
    glViewport(0, 0, fb_width, fb_height);
    glPixelZoom(static_cast<float>(fb_width) / static_cast<float>(o.width),
                static_cast<float>(fb_height) / static_cast<float>(o.height));
    glRasterPos2f(-1.0f, -1.0f);
    glDrawPixels(o.width, o.height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    glfwSwapBuffers(window);
  }
  glfwDestroyWindow(window);
  glfwTerminate();
  return status;
}
#endif

// Everything that can fail in Sinew's setup, checked in order.
api::Result<std::unique_ptr<Engine>> make_engine(const Options& o) {
  auto character = api::Character::load(o.pack);
  if (!character) return character.error();
  auto world = api::World::create();
  if (!world) return world.error();

  api::PassDesc desc;
  desc.width = o.width;
  desc.height = o.height;
  desc.outputs = api::Output::kColorRgba8 | api::Output::kDepth | api::Output::kInstanceId;
  desc.threads = o.threads;
  auto pass = api::RayTracePass::create(desc);
  if (!pass) return pass.error();
  desc.outputs = api::Output::kShadowMask;  // one light: one float a pixel
  auto shadow_pass = api::RayTracePass::create(desc);
  if (!shadow_pass) return shadow_pass.error();

  auto e = std::unique_ptr<Engine>(new Engine{std::move(*character), std::move(*world), std::move(*pass),
                                              std::move(*shadow_pass), {}, {}, {}, nullptr, {}, {}, {}, {},
                                              Frame(o.width, o.height), {}, api::kNoHit});
  for (int i = 0; i < o.instances; ++i) {
    api::InstanceDesc instance;
    instance.transform = api::Matrix3x4::translation(kInstanceSpacing * static_cast<float>(i), 0.0f, 0.0f);
    auto id = e->world.add_instance(e->character, instance);
    if (!id) return id.error();
    e->instances.push_back(*id);
  }
  // Measured at the bind pose, before anything is posed: the defaults then
  // do not depend on --clip and --time.
  auto framing = measure_world(e->world, e->character, o.instances);
  if (!framing) return framing.error();
  e->framing = *framing;
  e->ground = ground_under(*framing);

  // One camera and one light for both passes: that is what makes them one image.
  e->inputs.camera = o.camera ? *o.camera : default_camera(*framing, o.width, o.height);
  e->light.kind = api::Light::Kind::kPoint;
  e->light.position = o.light ? *o.light : default_light(*framing);
  // A sphere light: soft shadows on the characters and on the host's ground.
  e->light.radius =
      o.light_radius ? *o.light_radius : 0.1f * (axis(framing->high, framing->up_axis) - axis(framing->low, framing->up_axis));
  e->inputs.lights = {&e->light, 1};
  e->inputs.shadow_samples = o.shadow_samples;
  e->camera = host::PinholeCamera::from(e->inputs.camera, o.width, o.height);
  e->lighting.light_position = {e->light.position.x, e->light.position.y, e->light.position.z};
  e->lighting.ambient = {e->inputs.ambient.x, e->inputs.ambient.y, e->inputs.ambient.z};

  if (o.host_scheduler) {
    const int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    e->pool = std::make_unique<host::ThreadPool>(threads);
    e->scheduler = e->pool->scheduler();
  }
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const std::string error = parse_options(argc, argv, options); error == "help") {
    std::printf("%s", kUsage);
    return 0;
  } else if (!error.empty()) {
    std::fprintf(stderr, "host_engine: %s\n%s", error.c_str(), kUsage);
    return kExitUsage;
  }
#if !HOST_ENGINE_WINDOW
  if (!options.headless) {
    std::fprintf(stderr, "host_engine: built without GLFW/OpenGL: only --headless is available\n%s", kUsage);
    return kExitUsage;
  }
#endif
  auto engine = make_engine(options);
  if (!engine) return sinew_failed(engine.error());
  const api::Camera& c = (*engine)->inputs.camera;
  std::printf("%s: %zu bones, %zu triangles, %zu clips; camera %g,%g,%g,%g,%g,%g,%g,%g,%g,%g; %s scheduler\n",
              options.pack.c_str(), (*engine)->character.bone_count(), (*engine)->character.triangle_count(),
              (*engine)->character.clip_count(), static_cast<double>(c.eye.x), static_cast<double>(c.eye.y),
              static_cast<double>(c.eye.z), static_cast<double>(c.target.x), static_cast<double>(c.target.y),
              static_cast<double>(c.target.z), static_cast<double>(c.up.x), static_cast<double>(c.up.y),
              static_cast<double>(c.up.z), static_cast<double>(c.fovy_degrees),
              options.host_scheduler ? "host thread pool" : "TBB");
  if (options.headless) return run_headless(**engine, options);
#if HOST_ENGINE_WINDOW
  return run_windowed(**engine, options);
#else
  return kExitUsage;
#endif
}
