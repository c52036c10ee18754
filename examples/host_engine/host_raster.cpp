#include "host_raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace host {
namespace {

Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(float s, Vec3 v) { return {s * v.x, s * v.y, s * v.z}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
float length(Vec3 v) { return std::sqrt(dot(v, v)); }
Vec3 normalize(Vec3 v) { return (1.0f / length(v)) * v; }
Vec3 from_api(sinew::api::Float3 f) { return {f.x, f.y, f.z}; }
float& axis(Vec3& v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }
float axis(const Vec3& v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

// sRGB encoding through a table: pow() per channel would dominate the sky.
std::uint8_t to_srgb8(float linear) {
  constexpr int kSteps = 4096;
  static const std::array<std::uint8_t, kSteps + 1> table = [] {
    std::array<std::uint8_t, kSteps + 1> t{};
    for (int i = 0; i <= kSteps; ++i) {
      const float c = static_cast<float>(i) / kSteps;
      const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
      t[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(std::lround(255.0f * s));
    }
    return t;
  }();
  return table[static_cast<std::size_t>(std::clamp(linear, 0.0f, 1.0f) * kSteps + 0.5f)];
}

void put(std::uint8_t* rgba, Vec3 linear) {
  rgba[0] = to_srgb8(linear.x);
  rgba[1] = to_srgb8(linear.y);
  rgba[2] = to_srgb8(linear.z);
  rgba[3] = 255;
}

// A vertex after the view transform: camera-space coordinates (x right, y up,
// z along forward) and its world position, which perspective-correct
// interpolation recovers exactly at each pixel.
struct ViewVertex {
  Vec3 view;
  Vec3 world;
};

ViewVertex to_view(const PinholeCamera& camera, Vec3 world) {
  const Vec3 d = world - camera.eye;
  return {{dot(d, camera.right), dot(d, camera.up), dot(d, camera.forward)}, world};
}

// Ground corners that lie behind the eye would project through infinity:
// clip the polygon against a near plane first (Sutherland-Hodgman, one plane).
constexpr float kNearPlane = 1e-3f;

std::vector<ViewVertex> clip_near(const std::vector<ViewVertex>& polygon) {
  std::vector<ViewVertex> out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const ViewVertex& a = polygon[i];
    const ViewVertex& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a.view.z >= kNearPlane;
    const bool b_in = b.view.z >= kNearPlane;
    if (a_in) out.push_back(a);
    if (a_in != b_in) {
      const float t = (kNearPlane - a.view.z) / (b.view.z - a.view.z);
      out.push_back({a.view + t * (b.view - a.view), a.world + t * (b.world - a.world)});
    }
  }
  return out;
}

// Double precision: a corner clipped at the near plane projects thousands
// of pixels off screen, and float edge functions there lose whole pixels.
struct ScreenPoint {
  double x;  // pixel units: pixel (i, j)'s centre is (i + 0.5, j + 0.5)
  double y;
};

// The inverse of ray_direction: where a camera-space point lands on screen.
ScreenPoint project(const PinholeCamera& camera, Vec3 view) {
  const double sx = double{view.x} / (double{view.z} * double{camera.tan_half_fovy} * double{camera.aspect});
  const double sy = double{view.y} / (double{view.z} * double{camera.tan_half_fovy});
  return {0.5 * (sx + 1.0) * camera.width, 0.5 * (1.0 - sy) * camera.height};
}

double edge(ScreenPoint a, ScreenPoint b, double px, double py) {
  return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

// A checkerboard, so the ground visibly moves with the camera, lit by the
// point light: the host's own shading, with only the shadow from Sinew.
Vec3 shade_ground(const Ground& ground, const HostLighting& lighting, Vec3 world, Vec3 normal, float shadow) {
  const int a = (ground.up_axis + 1) % 3;
  const int b = (ground.up_axis + 2) % 3;
  const auto cell = static_cast<long>(std::floor(axis(world, a) / ground.checker_size)) +
                    static_cast<long>(std::floor(axis(world, b) / ground.checker_size));
  const float albedo = (cell & 1) != 0 ? 0.35f : 0.6f;
  const float lambert = shadow * std::max(0.0f, dot(normal, normalize(lighting.light_position - world)));
  return albedo * (lighting.ambient + Vec3{lambert, lambert, lambert});
}

void draw_triangle(const PinholeCamera& camera, const std::array<ViewVertex, 3>& tri, Vec3 normal,
                   GBuffer& gbuffer) {
  const ScreenPoint p0 = project(camera, tri[0].view);
  const ScreenPoint p1 = project(camera, tri[1].view);
  const ScreenPoint p2 = project(camera, tri[2].view);
  const double area = edge(p0, p1, p2.x, p2.y);
  if (area == 0.0 || !std::isfinite(area)) return;  // degenerate, or a degenerate camera
  // Clamped to the image in double first: off-screen corners may lie far
  // beyond int's range.
  const auto clamped = [](double v, int limit) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(limit))); };
  const int x_begin = clamped(std::floor(std::min({p0.x, p1.x, p2.x})), camera.width);
  const int x_end = clamped(std::ceil(std::max({p0.x, p1.x, p2.x})), camera.width);
  const int y_begin = clamped(std::floor(std::min({p0.y, p1.y, p2.y})), camera.height);
  const int y_end = clamped(std::ceil(std::max({p0.y, p1.y, p2.y})), camera.height);
  for (int y = y_begin; y < y_end; ++y) {
    float* depth_row = gbuffer.depth.row<float>(y);
    Vec3* position_row = gbuffer.position.row<Vec3>(y);
    Vec3* normal_row = gbuffer.normal.row<Vec3>(y);
    const double py = y + 0.5;
    for (int x = x_begin; x < x_end; ++x) {
      const double px = x + 0.5;
      // Barycentrics in screen space, signed by the winding so both work.
      const double b0 = edge(p1, p2, px, py) / area;
      const double b1 = edge(p2, p0, px, py) / area;
      const double b2 = edge(p0, p1, px, py) / area;
      if (b0 < 0.0 || b1 < 0.0 || b2 < 0.0) continue;
      // Perspective-correct: weights b_i / z_i recover the world point on the
      // triangle that the pixel's ray hits, hence the ray distance exactly.
      const double w0 = b0 / double{tri[0].view.z};
      const double w1 = b1 / double{tri[1].view.z};
      const double w2 = b2 / double{tri[2].view.z};
      const double inv = 1.0 / (w0 + w1 + w2);
      const Vec3 world = static_cast<float>(w0 * inv) * tri[0].world + static_cast<float>(w1 * inv) * tri[1].world +
                         static_cast<float>(w2 * inv) * tri[2].world;
      const float distance = length(world - camera.eye);
      if (distance >= depth_row[x]) continue;
      depth_row[x] = distance;
      position_row[x] = world;
      normal_row[x] = normal;
    }
  }
}

}  // namespace

Image::Image(int width, int height, std::size_t bytes_per_pixel)
    : width_(width),
      height_(height),
      row_pitch_((static_cast<std::size_t>(width) * bytes_per_pixel + kRowAlignment - 1) / kRowAlignment *
                 kRowAlignment),
      storage_(row_pitch_ / sizeof(std::uint32_t) * static_cast<std::size_t>(height)) {}

PinholeCamera PinholeCamera::from(const sinew::api::Camera& camera, int width, int height) {
  PinholeCamera c;
  c.eye = from_api(camera.eye);
  c.forward = normalize(from_api(camera.target) - c.eye);
  c.right = normalize(cross(c.forward, from_api(camera.up)));
  c.up = cross(c.right, c.forward);
  c.tan_half_fovy = std::tan(0.5f * camera.fovy_degrees * 3.14159265f / 180.0f);
  c.aspect = static_cast<float>(width) / static_cast<float>(height);
  c.width = width;
  c.height = height;
  return c;
}

Vec3 PinholeCamera::ray_direction(int x, int y) const {
  const float sx = 2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(width) - 1.0f;
  const float sy = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
  return normalize(forward + (sx * tan_half_fovy * aspect) * right + (sy * tan_half_fovy) * up);
}

void draw_host_gbuffer(const PinholeCamera& camera, const Ground& ground, GBuffer& gbuffer) {
  // Nothing drawn yet: depth +inf, and no surface for Sinew's rays.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < camera.height; ++y) {
    std::fill_n(gbuffer.depth.row<float>(y), camera.width, kFarAway);
    std::fill_n(gbuffer.position.row<Vec3>(y), camera.width, Vec3{nan, nan, nan});
    std::fill_n(gbuffer.normal.row<Vec3>(y), camera.width, Vec3{});
  }

  const int a = (ground.up_axis + 1) % 3;
  const int b = (ground.up_axis + 2) % 3;
  std::vector<ViewVertex> quad;
  for (const auto& [da, db] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
    Vec3 corner = ground.center;
    axis(corner, ground.up_axis) = ground.height;
    axis(corner, a) += da * ground.half_size;
    axis(corner, b) += db * ground.half_size;
    quad.push_back(to_view(camera, corner));
  }
  // The quad (two triangles) is convex: clip it as one polygon, draw the
  // part in front of the eye as a fan of triangles.
  const std::vector<ViewVertex> visible = clip_near(quad);
  Vec3 up;
  axis(up, ground.up_axis) = 1.0f;
  for (std::size_t i = 1; i + 1 < visible.size(); ++i) {
    draw_triangle(camera, {visible[0], visible[i], visible[i + 1]}, up, gbuffer);
  }
}

void shade_host_pass(const PinholeCamera& camera, const Ground& ground, const HostLighting& lighting,
                     const GBuffer& gbuffer, const Image& shadow, Image& color) {
  for (int y = 0; y < camera.height; ++y) {
    std::uint8_t* color_row = color.row<std::uint8_t>(y);
    const float* depth_row = gbuffer.depth.row<float>(y);
    const Vec3* position_row = gbuffer.position.row<Vec3>(y);
    const Vec3* normal_row = gbuffer.normal.row<Vec3>(y);
    const float* shadow_row = shadow.row<float>(y);
    for (int x = 0; x < camera.width; ++x) {
      if (depth_row[x] == kFarAway) {
        // Sky: a gradient on the view ray's elevation.
        const float elevation = std::clamp(axis(camera.ray_direction(x, y), ground.up_axis), 0.0f, 1.0f);
        const float t = std::sqrt(elevation);
        put(color_row + 4 * x, (1.0f - t) * Vec3{0.75f, 0.80f, 0.85f} + t * Vec3{0.20f, 0.35f, 0.70f});
        continue;
      }
      put(color_row + 4 * x, shade_ground(ground, lighting, position_row[x], normal_row[x], shadow_row[x]));
    }
  }
}

void composite_by_depth(const Image& sinew_color, const Image& sinew_depth, Image& host_color,
                        Image& host_depth) {
  for (int y = 0; y < host_color.height(); ++y) {
    const std::uint8_t* from_color = sinew_color.row<std::uint8_t>(y);
    const float* from_depth = sinew_depth.row<float>(y);
    std::uint8_t* to_color = host_color.row<std::uint8_t>(y);
    float* to_depth = host_depth.row<float>(y);
    for (int x = 0; x < host_color.width(); ++x) {
      if (from_depth[x] < to_depth[x]) {
        std::copy_n(from_color + 4 * x, 4, to_color + 4 * x);
        to_depth[x] = from_depth[x];
      }
    }
  }
}

void highlight_instance(const Image& instance_ids, const Image& sinew_depth, std::uint32_t selected,
                        Image& host_color, const Image& host_depth) {
  // In sRGB bytes, like the frame: a highlight needs no linear light.
  constexpr std::array<int, 3> kOrange{255, 140, 0};
  for (int y = 0; y < host_color.height(); ++y) {
    const std::uint32_t* ids = instance_ids.row<std::uint32_t>(y);
    const float* from_depth = sinew_depth.row<float>(y);
    const float* to_depth = host_depth.row<float>(y);
    std::uint8_t* color_row = host_color.row<std::uint8_t>(y);
    for (int x = 0; x < host_color.width(); ++x) {
      if (ids[x] != selected || from_depth[x] != to_depth[x]) continue;
      std::uint8_t* rgb = color_row + 4 * x;
      for (std::size_t c = 0; c < kOrange.size(); ++c) {
        rgb[c] = static_cast<std::uint8_t>((rgb[c] + kOrange[c] + 1) / 2);
      }
    }
  }
}

}  // namespace host
