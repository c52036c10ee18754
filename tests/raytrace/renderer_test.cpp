// The renderer (render/renderer.h) end to end: characters look fine where
// their projected boxes hold about a pixel per triangle, split shadow
// packets shade as single rays, and the renderer matches single rays and
// brute force for packets that straddle tile and image edges, cameras
// inside a character and rays starting inside bone boxes; staged and
// in-place outputs hold the same bytes, and colour alone the bytes of a
// render of every output.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "runtime/memory/line_aligned.h"
#include "tests/raytrace/render_test_support.h"
#include "tests/support/aov_frame.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::kTests;
using testing_support::scene;

struct Frame {
  std::vector<std::uint8_t> color;
  std::vector<float> depth;
  std::vector<Vec3> normal;
  std::vector<std::uint32_t> triangle, instance;
};

Frame render(const rt::Scene& sc, const rt::PinholeCamera& camera, int tile, int packet_rays, TriangleTest test,
             JobSystem& jobs) {
  const std::size_t n = static_cast<std::size_t>(camera.width() * camera.height());
  Frame f;
  f.color.resize(4 * n);
  f.depth.resize(n);
  f.normal.resize(n);
  f.triangle.resize(n);
  f.instance.resize(n);
  rt::FrameBuffers buffers{camera.width(), camera.height(), f.color, {}, f.depth, f.normal, f.triangle, f.instance, {}, {}, {}, {}, {}, {}};
  rt::RenderSettings settings;
  settings.tile_size = tile;
  settings.packet_rays = packet_rays;
  settings.triangle_test = test;
  rt::Renderer renderer;
  EXPECT_TRUE(renderer.render(sc, camera, settings, buffers, jobs).ok());
  return f;
}

// One idle mannequin, nothing else.
std::unique_ptr<rt::Scene> one_mannequin() {
  const testing_support::BakedModel& m = testing_support::idle_mannequin();
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene->add_instance(character).value();
  EXPECT_TRUE(scene->set_bones(instance, testing_support::clip_pose(m.model, "idle", 0.3, Affine3::identity())).ok());
  JobSystem jobs(2);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  return scene;
}

// By hand: a camera on the axis through the box's centre, looking along -z,
// sees the box's near face widest, dx / z_near by dy / z_near in slope, at
// H / (2 tan(fovy / 2)) pixels per unit of slope on a square image. Image
// sizes put that at 1.6 and 2.5 pixels per triangle, either side of
// kFineBoxPixelsPerTriangle (2).
TEST(Renderer, CharactersLookFineWhereTheirProjectedBoxesHoldAboutAPixelPerTriangle) {
  const std::unique_ptr<rt::Scene> sc = one_mannequin();
  Aabb box = Aabb::empty();
  for (const Aabb& b : sc->instances()[0].bone_world_boxes) box.extend(b);
  ASSERT_TRUE(box.lower.x < box.upper.x);
  const double triangles = static_cast<double>(sc->characters()[0].mesh->triangles.size());
  const Vec3 centre = box.center();
  const double dx = box.upper.x - box.lower.x, dy = box.upper.y - box.lower.y, dz = box.upper.z - box.lower.z;
  const double distance = 6.0;  // eye to the box's centre
  const double z_near = distance - 0.5 * dz;
  const double fovy = 30.0, tan_half = std::tan(fovy * 0.5 * std::acos(-1.0) / 180.0);
  const Vec3 eye = centre + Vec3(0.0f, 0.0f, static_cast<float>(distance));
  for (const double per_triangle : {1.6, 2.5}) {
    // pixels = (dx / z_near) (dy / z_near) (H / (2 tan))^2 = per_triangle * triangles.
    const int size = static_cast<int>(
        std::lround(2.0 * tan_half * z_near * std::sqrt(per_triangle * triangles / (dx * dy))));
    const double s = size / (2.0 * tan_half);
    const double expected = (dx / z_near) * (dy / z_near) * s * s / triangles;
    ASSERT_NEAR(expected, per_triangle, 0.1) << size;
    const auto camera = rt::PinholeCamera::create({eye, centre, Vec3(0, 1, 0), static_cast<float>(fovy)}, size, size);
    ASSERT_TRUE(camera.ok());
    EXPECT_EQ(rt::characters_look_fine(*sc, *camera), expected <= rt::kFineBoxPixelsPerTriangle)
        << size << " px: " << expected << " pixels per triangle";
  }
  // An eye inside the box: coarse, however small the image.
  const auto inside = rt::PinholeCamera::create({centre, centre - Vec3(0, 0, 1), Vec3(0, 1, 0), 30.0f}, 1, 1);
  ASSERT_TRUE(inside.ok());
  EXPECT_FALSE(rt::characters_look_fine(*sc, *inside));
  // No character at all.
  const rt::Scene empty;
  const auto far = rt::PinholeCamera::create({eye, centre, Vec3(0, 1, 0), 30.0f}, 1, 1);
  ASSERT_TRUE(far.ok());
  EXPECT_FALSE(rt::characters_look_fine(empty, *far));
  EXPECT_TRUE(rt::characters_look_fine(*sc, *far));
}

// Far from the camera the mannequins' triangles are a pixel or less: the
// regions split, and the image is the single rays' either way.
TEST(Renderer, SplitShadowPacketsOnFineTrianglesShadeAsSingleRays) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 14.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 8.0f}, 67, 61)
          .value();
  const std::size_t n = static_cast<std::size_t>(camera.width() * camera.height());
  const auto color = [&](int packet_rays, bool split, rt::TraversalCounters* shadow) {
    std::vector<std::uint8_t> rgba(4 * n);
    rt::FrameBuffers buffers{camera.width(), camera.height(), rgba, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}};
    rt::RenderSettings settings;
    settings.packet_rays = packet_rays;
    settings.split_fine_shadow_packets = split;
    rt::Renderer renderer;
    const Expected<rt::RenderStats> stats = renderer.render(sc, camera, settings, buffers, jobs);
    EXPECT_TRUE(stats.ok());
    if (shadow != nullptr && stats.ok()) *shadow = stats->shadow;
    return rgba;
  };
  const std::vector<std::uint8_t> single = color(1, true, nullptr);
  for (const int packet_rays : {256, 512}) {
    rt::TraversalCounters whole, split;
    EXPECT_EQ(color(packet_rays, false, &whole), single) << packet_rays;
    EXPECT_EQ(color(packet_rays, true, &split), single) << packet_rays;
    // Smaller packets walk the trees otherwise: the split happened.
    EXPECT_TRUE(split.node_visits != whole.node_visits || split.triangle_tests != whole.triangle_tests)
        << packet_rays;
  }
}

// Odd image sizes and tile sizes put partial 4x2 blocks on every tile and
// image edge; cameras inside a character and inside a bone box start rays
// inside objects. Every pixel is checked against the single-ray query and
// against brute force, and packets against single rays for the whole image.
TEST(Renderer, PacketsMatchSingleRaysAndBruteForceAtEdgesAndInsideCharacters) {
  const rt::Scene& sc = scene();
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  JobSystem jobs(2);
  const Aabb chest = sc.top_level().objects()[sc.top_level().objects().size() / 3].box;
  const rt::CameraDesc cameras[] = {
      {Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f},   // outside
      {Vec3(-0.45f, 1.2f, 0.02f), Vec3(0.5f, 0.8f, -1.0f), Vec3(0, 1, 0), 100.0f},  // inside a mannequin
      {chest.center(), chest.center() + Vec3(0.3f, -0.2f, 1.0f), Vec3(0, 1, 0), 120.0f},  // inside a bone box
  };
  const std::pair<int, int> sizes[] = {{37, 23}, {29, 31}};
  std::size_t checked = 0, character = 0;
  for (const rt::CameraDesc& desc : cameras) {
    for (const auto& [w, h] : sizes) {
      const auto camera = rt::PinholeCamera::create(desc, w, h).value();
      for (const TriangleTest test : kTests) {
        const Frame single = render(sc, camera, 16, 1, test, jobs);
        for (const int packet_rays : {8, 64, 256, 512}) {
          for (const int tile : {1, 3, 5, 16, 64}) {
            const Frame packets = render(sc, camera, tile, packet_rays, test, jobs);
            EXPECT_EQ(packets.triangle, single.triangle) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.instance, single.instance) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.depth, single.depth) << "tile " << tile << ", " << packet_rays << " rays";
            EXPECT_EQ(packets.color, single.color) << "tile " << tile << ", " << packet_rays << " rays";
          }
        }
        for (int y = 0; y < h; ++y) {
          for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y * w + x);
            const Ray ray = camera.ray(x, y);
            const Hit ours{single.depth[i] / glm::length(ray.direction), 0.0f, 0.0f, single.triangle[i],
                           single.instance[i]};
            const Hit ref = testing_support::nearest(soup, ray, test);
            ++checked;
            character += ref.valid() && ref.instance_id < 2 ? 1 : 0;
            ASSERT_EQ(single.triangle[i], rt::intersect(sc, ray, test).triangle_id) << x << "," << y;
            ASSERT_TRUE(testing_support::same_nearest(rt::intersect(sc, ray, test), ref, soup, ray, test))
                << x << "," << y << " tri " << ours.triangle_id << " ref " << ref.triangle_id;
          }
        }
      }
    }
  }
  EXPECT_GT(character, checked / 10);
}

// Bytes per pixel of each output, in FrameBuffers order: RGBA8, RGBA32F,
// depth, normal, triangle id, instance id.
constexpr std::size_t kOutputPixelBytes[] = {4, 16, 4, sizeof(Vec3), 4, 4};

// One host plane: `rows` rows `pitch` bytes apart, starting `offset` bytes
// into line-aligned storage filled with a sentinel byte (and a little more,
// so that the span's whole elements reach the last row's end).
struct HostPlane {
  LineAlignedVector<std::byte> bytes;
  std::size_t offset = 0, pitch = 0;
  HostPlane(std::size_t offset_bytes, std::size_t pitch_bytes, int rows)
      : bytes(offset_bytes + pitch_bytes * static_cast<std::size_t>(rows) + 16, std::byte{0xA5}),
        offset(offset_bytes),
        pitch(pitch_bytes) {}
  template <class T>
  std::span<T> span() {
    return {reinterpret_cast<T*>(bytes.data() + offset), (bytes.size() - offset) / sizeof(T)};
  }
};

// Every output, laid out with each row `row_bytes(output)` rounded up to a
// multiple of `align` plus `pad` bytes, starting `offset` bytes past a line.
struct HostFrame {
  std::vector<HostPlane> planes;
  rt::FrameBuffers buffers;
  HostFrame(int w, int h, std::size_t align, std::size_t pad, std::size_t offset) {
    for (const std::size_t bytes_per_pixel : kOutputPixelBytes) {
      const std::size_t row = bytes_per_pixel * static_cast<std::size_t>(w);
      planes.emplace_back(offset, (row + align - 1) / align * align + pad, h);
    }
    buffers.width = w;
    buffers.height = h;
    buffers.color_rgba8 = planes[0].span<std::uint8_t>();
    buffers.color_rgba32f = planes[1].span<float>();
    buffers.depth = planes[2].span<float>();
    buffers.normal = planes[3].span<Vec3>();
    buffers.triangle_id = planes[4].span<std::uint32_t>();
    buffers.instance_id = planes[5].span<std::uint32_t>();
    buffers.row_pitch = {planes[0].pitch, planes[1].pitch, planes[2].pitch,
                         planes[3].pitch, planes[4].pitch, planes[5].pitch};
  }
  // Plane p's row y: its pixels, and the padding after them.
  std::span<const std::byte> row(std::size_t p, int y, std::size_t row_bytes) const {
    return {planes[p].bytes.data() + planes[p].offset + static_cast<std::size_t>(y) * planes[p].pitch, row_bytes};
  }
  std::span<const std::byte> padding(std::size_t p, int y, std::size_t row_bytes) const {
    return {planes[p].bytes.data() + planes[p].offset + static_cast<std::size_t>(y) * planes[p].pitch + row_bytes,
            planes[p].pitch - row_bytes};
  }
};

// Rows that start on a line are staged and stored by streaming whole lines
// (render/output/output_staging.h); the others are written in place. Both must
// give every output the same bytes, and neither may touch the padding
// between rows, whatever the tile and image edges do to the lines.
TEST(Renderer, StagedAndInPlaceOutputsHoldTheSameBytes) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const rt::CameraDesc desc{Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f};
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 40}}) {
    const auto camera = rt::PinholeCamera::create(desc, w, h).value();
    for (const int tile : {5, 16, 32}) {
      rt::RenderSettings settings;
      settings.tile_size = tile;
      // In place: rows 4 bytes past a line. Staged: rows on lines, packed
      // where the row is whole lines, else padded to them, or padded further.
      HostFrame in_place(w, h, 4, 0, 4);
      HostFrame staged(w, h, 64, 0, 0);
      HostFrame staged_padded(w, h, 64, 128, 0);
      rt::Renderer renderer;
      ASSERT_TRUE(renderer.render(sc, camera, settings, in_place.buffers, jobs).ok());
      ASSERT_TRUE(renderer.render(sc, camera, settings, staged.buffers, jobs).ok());
      ASSERT_TRUE(renderer.render(sc, camera, settings, staged_padded.buffers, jobs).ok());
      for (std::size_t p = 0; p < 6; ++p) {
        const std::size_t row_bytes = kOutputPixelBytes[p] * static_cast<std::size_t>(w);
        for (int y = 0; y < h; ++y) {
          const auto reference = in_place.row(p, y, row_bytes);
          for (const HostFrame* frame : {&staged, &staged_padded}) {
            const auto row = frame->row(p, y, row_bytes);
            ASSERT_TRUE(std::equal(row.begin(), row.end(), reference.begin()))
                << "plane " << p << " row " << y << " tile " << tile << " " << w << "x" << h;
            for (const std::byte b : frame->padding(p, y, row_bytes)) ASSERT_EQ(b, std::byte{0xA5}) << "plane " << p;
          }
          for (const std::byte b : in_place.padding(p, y, row_bytes)) ASSERT_EQ(b, std::byte{0xA5}) << "plane " << p;
        }
      }
      // The reference is the packed render of the test above, pixel for
      // pixel, and sees the characters.
      const Frame packed = render(sc, camera, tile, 64, TriangleTest::kFast, jobs);
      EXPECT_GT(std::count_if(packed.instance.begin(), packed.instance.end(),
                              [](std::uint32_t id) { return id < 2; }),
                w * h / 20);
      for (int y = 0; y < h; ++y) {
        const auto row = in_place.row(4, y, 4 * static_cast<std::size_t>(w));
        ASSERT_TRUE(std::equal(row.begin(), row.end(),
                               reinterpret_cast<const std::byte*>(packed.triangle.data() + y * w)))
            << "row " << y;
      }
    }
  }
}

// Colour alone (a game's frame) takes its own path through the shading
// (shade_rgba8_only, render/stages/shade.cpp); its bytes must be those of a
// render that asks for every output, staged or in place, with partial
// blocks at the image's edges and lights of both kinds.
TEST(Renderer, ColourAloneHoldsTheBytesOfARenderOfEveryOutput) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const rt::CameraDesc desc{Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f};
  rt::Light lights[2];
  lights[0].position = Vec3(-2.0f, 5.0f, 3.0f);
  lights[0].color = Vec3(0.9f, 0.6f, 0.3f);
  lights[1].kind = rt::Light::Kind::kDirectional;
  lights[1].direction = Vec3(0.5f, 1.0f, -0.2f);
  lights[1].color = Vec3(0.2f, 0.3f, 0.5f);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 40}}) {
    const auto camera = rt::PinholeCamera::create(desc, w, h).value();
    const std::size_t row_bytes = 4 * static_cast<std::size_t>(w);
    for (const std::size_t light_count : {std::size_t{1}, std::size_t{2}}) {
      for (const int tile : {5, 16, 32}) {
        rt::RenderSettings settings;
        settings.tile_size = tile;
        settings.lights = std::span<const rt::Light>(lights, light_count);
        HostFrame every(w, h, 64, 0, 0);
        rt::Renderer renderer;
        ASSERT_TRUE(renderer.render(sc, camera, settings, every.buffers, jobs).ok());
        std::size_t on_character = 0;
        for (int y = 0; y < h; ++y) {
          const auto ids = every.row(5, y, row_bytes);
          for (int x = 0; x < w; ++x) {
            std::uint32_t id;
            std::memcpy(&id, ids.data() + 4 * x, 4);
            on_character += id < 2 ? 1 : 0;
          }
        }
        EXPECT_GT(on_character, static_cast<std::size_t>(w * h / 20));
        // Staged (rows on lines) and in place (rows 4 bytes past a line).
        for (const auto& [align, offset] : {std::pair<std::size_t, std::size_t>{64, 0}, {4, 4}}) {
          HostPlane color(offset, (row_bytes + align - 1) / align * align, h);
          rt::FrameBuffers only;
          only.width = w;
          only.height = h;
          only.color_rgba8 = color.span<std::uint8_t>();
          only.row_pitch.color_rgba8 = color.pitch;
          ASSERT_TRUE(renderer.render(sc, camera, settings, only, jobs).ok());
          for (int y = 0; y < h; ++y) {
            const auto reference = every.row(0, y, row_bytes);
            const std::byte* row = color.bytes.data() + offset + static_cast<std::size_t>(y) * color.pitch;
            ASSERT_TRUE(std::equal(reference.begin(), reference.end(), row))
                << "row " << y << " tile " << tile << " " << w << "x" << h << ", " << light_count << " lights";
            for (std::size_t i = row_bytes; i < color.pitch; ++i) ASSERT_EQ(row[i], std::byte{0xA5});
          }
        }
      }
    }
  }
}


// Several lights, each with its own share of the colour. Two point lights
// and a directional one, each in one colour channel and with no ambient:
// channel c of the linear colour is light c's contribution alone. Against
// brute force over every triangle: where the hit's geometric normal faces
// light c and a shadow ray from the hit reaches it, the channel is the
// albedo times N·L of the shading normal; elsewhere it is 0. Pixels whose
// brute-force answer depends on the shadow ray's offset from the surface,
// or that lie on the terminator, are left out.
TEST(Renderer, EachLightsContributionIsItsBruteForceVisibilityTimesNdotL) {
  const rt::Scene& sc = scene();
  JobSystem jobs(2);
  const int w = 80, h = 60;
  const rt::CameraDesc desc{Vec3(0.5f, 1.8f, 3.5f), Vec3(0.0f, 0.6f, 0.0f), Vec3(0, 1, 0), 50.0f};
  const auto camera = rt::PinholeCamera::create(desc, w, h).value();
  rt::Light lights[3];
  lights[0].position = Vec3(-2.0f, 5.0f, 3.0f);
  lights[0].color = Vec3(1.0f, 0.0f, 0.0f);
  lights[1].position = Vec3(3.0f, 3.0f, -1.0f);
  lights[1].color = Vec3(0.0f, 1.0f, 0.0f);
  lights[2].kind = rt::Light::Kind::kDirectional;
  lights[2].direction = Vec3(0.5f, 1.0f, -0.2f);
  lights[2].color = Vec3(0.0f, 0.0f, 1.0f);
  rt::RenderSettings settings;
  settings.lights = lights;
  settings.ambient = Vec3(0.0f);
  HostFrame lit(w, h, 64, 0, 0);
  rt::Renderer renderer;
  ASSERT_TRUE(renderer.render(sc, camera, settings, lit.buffers, jobs).ok());
  // The albedo: ambient 1 and dark lights.
  rt::Light dark[1];
  dark[0].color = Vec3(0.0f);
  rt::RenderSettings albedo_settings;
  albedo_settings.lights = dark;
  albedo_settings.ambient = Vec3(1.0f);
  HostFrame albedo(w, h, 64, 0, 0);
  ASSERT_TRUE(renderer.render(sc, camera, albedo_settings, albedo.buffers, jobs).ok());

  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(sc);
  const auto occluded = [&](const Vec3& from, const rt::Light& light) {
    Ray ray;
    ray.origin = from;
    ray.t_min = 0.0f;
    if (light.kind == rt::Light::Kind::kPoint) {
      ray.direction = light.position - from;
      ray.t_max = 1.0f;
    } else {
      ray.direction = light.direction;
      ray.t_max = testing_support::kInf;
    }
    return testing_support::nearest(soup, ray, TriangleTest::kWatertight).valid();
  };
  const auto pixel = [](const HostFrame& f, std::size_t plane, std::size_t bytes, int x, int y) {
    return f.planes[plane].bytes.data() + f.planes[plane].offset + static_cast<std::size_t>(y) * f.planes[plane].pitch +
           bytes * static_cast<std::size_t>(x);
  };
  int checked[3] = {0, 0, 0}, shadowed[3] = {0, 0, 0};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint32_t triangle, instance;
      std::memcpy(&triangle, pixel(lit, 4, 4, x, y), 4);
      std::memcpy(&instance, pixel(lit, 5, 4, x, y), 4);
      if (instance == kInvalidId) continue;
      float depth, color[4], base[4];
      Vec3 n;
      std::memcpy(&depth, pixel(lit, 2, 4, x, y), 4);
      std::memcpy(&n, pixel(lit, 3, sizeof(Vec3), x, y), sizeof(Vec3));
      std::memcpy(color, pixel(lit, 1, 16, x, y), 16);
      std::memcpy(base, pixel(albedo, 1, 16, x, y), 16);
      const Ray eye = camera.ray(x, y);
      const Vec3 p = eye.origin + depth * eye.direction;
      const auto tri = std::find_if(soup.begin(), soup.end(), [&](const testing_support::SoupTriangle& t) {
        return t.triangle_id == triangle && t.instance_id == instance;
      });
      ASSERT_NE(tri, soup.end()) << "pixel " << x << "," << y;
      Vec3 g = glm::normalize(glm::cross(tri->p1 - tri->p0, tri->p2 - tri->p0));
      if (glm::dot(g, eye.direction) > 0.0f) g = -g;
      for (int c = 0; c < 3; ++c) {
        const rt::Light& light = lights[c];
        const Vec3 to = light.kind == rt::Light::Kind::kPoint ? light.position - p : light.direction;
        const Vec3 l = glm::normalize(to);
        if (std::fabs(glm::dot(g, l)) < 1e-3f) continue;  // the terminator
        bool blocked = glm::dot(g, l) < 0.0f;
        if (!blocked) {
          const bool near = occluded(p + 1e-4f * g, light), far = occluded(p + 1e-3f * g, light);
          if (near != far) continue;  // an occluder within the offsets: the test's own rounding decides
          blocked = near;
        }
        const float expected = blocked ? 0.0f : base[c] * std::max(glm::dot(n, l), 0.0f);
        ++checked[c];
        shadowed[c] += blocked && glm::dot(g, l) > 0.0f ? 1 : 0;
        EXPECT_NEAR(color[c], expected, 2e-3f) << "light " << c << " pixel " << x << "," << y << " instance "
                                               << instance << (blocked ? " (blocked)" : " (lit)");
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(checked[c], w * h / 3) << "light " << c;
    EXPECT_GT(shadowed[c], 20) << "light " << c << " casts no shadow in view";
  }
}

// Masks (Scene::set_mask, RenderSettings::camera_mask and shadow_mask):
// the image is what brute force over the unmasked objects gives. Camera
// rays see only objects sharing a bit with camera_mask, shadow rays are
// blocked only by those sharing a bit with shadow_mask.
TEST(Renderer, MasksLeaveObjectsOutOfCameraRaysOrShadowRaysAsBruteForceOverTheRestDoes) {
  std::unique_ptr<rt::Scene> sc = testing_support::make_scene();  // mannequins 0 and 1, the ground 2
  const std::uint32_t masks[3] = {1u, 2u, 4u};
  for (std::uint32_t id = 0; id < 3; ++id) ASSERT_TRUE(sc->set_mask(id, masks[id]).ok());
  JobSystem jobs(2);
  const int w = 80, h = 60;
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.5f, 1.8f, 3.5f), Vec3(0.0f, 0.6f, 0.0f), Vec3(0, 1, 0), 50.0f}, w, h).value();
  rt::Light light[1];
  light[0].position = Vec3(-2.0f, 5.0f, 3.0f);
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(*sc);
  struct Round {
    std::uint32_t camera_mask, shadow_mask;
  };
  // Mannequin 1 casts shadows but is not drawn; mannequin 0 is drawn but
  // casts none. Then the ground and mannequin 0 drawn, only mannequin 1
  // casting.
  for (const Round round : {Round{~2u, ~1u}, Round{5u, 2u}}) {
    SCOPED_TRACE(round.camera_mask);
    rt::RenderSettings settings;
    settings.lights = light;
    settings.ambient = Vec3(0.0f);
    settings.camera_mask = round.camera_mask;
    settings.shadow_mask = round.shadow_mask;
    testing_support::AovFrame frame(w, h);
    rt::Renderer renderer;
    ASSERT_TRUE(renderer.render(*sc, camera, settings, frame.buffers(), jobs).ok());
    const std::vector<float>& color = frame.rgba32f;
    const std::vector<Vec3>& normal = frame.normal;
    const std::vector<std::uint32_t>& triangle = frame.triangle_id;
    const std::vector<std::uint32_t>& instance = frame.instance_id;
    std::vector<testing_support::SoupTriangle> seen, casting;
    for (const testing_support::SoupTriangle& t : soup) {
      if ((masks[t.instance_id] & round.camera_mask) != 0) seen.push_back(t);
      if ((masks[t.instance_id] & round.shadow_mask) != 0) casting.push_back(t);
    }
    int same = 0, lit = 0, shadowed = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t p = static_cast<std::size_t>(y * w + x);
        if (instance[p] != kInvalidId) {
          ASSERT_NE(masks[instance[p]] & round.camera_mask, 0u) << "a masked object drawn";
        }
        const Ray eye = camera.ray(x, y);
        const Hit hit = testing_support::nearest(seen, eye, TriangleTest::kFast);
        if (!hit.valid()) {
          EXPECT_EQ(instance[p], kInvalidId) << x << "," << y;
          continue;
        }
        if (hit.instance_id != instance[p] || hit.triangle_id != triangle[p]) continue;  // an edge
        ++same;
        const auto tri = std::find_if(seen.begin(), seen.end(), [&](const testing_support::SoupTriangle& t) {
          return t.triangle_id == hit.triangle_id && t.instance_id == hit.instance_id;
        });
        Vec3 g = glm::normalize(glm::cross(tri->p1 - tri->p0, tri->p2 - tri->p0));
        if (glm::dot(g, eye.direction) > 0.0f) g = -g;
        const Vec3 point = eye.origin + hit.t * eye.direction;
        const Vec3 to_light = light[0].position - point;
        // Facing away or at the terminator, by either normal (the shading
        // normal's N.L is the colour's factor).
        if (glm::dot(g, glm::normalize(to_light)) < 1e-3f || glm::dot(normal[p], glm::normalize(to_light)) < 1e-3f) {
          continue;
        }
        const auto blocked_from = [&](const Vec3& from) {
          Ray ray;
          ray.origin = from;
          ray.direction = light[0].position - from;
          ray.t_max = 1.0f;
          return testing_support::nearest(casting, ray, TriangleTest::kWatertight).valid();
        };
        const bool near = blocked_from(point + 1e-4f * g), far = blocked_from(point + 1e-3f * g);
        if (near != far) continue;  // an occluder within the offsets: the test's own rounding decides
        EXPECT_EQ(color[4 * p] > 0.0f, !near) << "pixel " << x << "," << y << " instance " << instance[p];
        (near ? shadowed : lit) += 1;
      }
    }
    EXPECT_GT(same, w * h / 3);
    EXPECT_GT(lit, 200);
    EXPECT_GT(shadowed, 20) << "some shadow in view";
  }
}

}  // namespace
}  // namespace sinew
