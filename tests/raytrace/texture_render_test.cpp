// Textured materials in the renderer, against an independent reference:
// each pixel's nearest triangle and barycentrics by brute force over the
// posed triangles, its uv interpolated from them, and the source image
// (floats, before the texture's 16-bit storage) sampled bilinearly in
// double precision here. Magnified, the rendered albedo matches it within
// 1/255; minified far away, a one-texel checkerboard averages to grey
// instead of aliasing, which only a coarser mip level gives.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "runtime/image/texture.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/aov_frame.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

// The source image: `side` x `side` linear RGB values, a function of the
// texel (a checkerboard of 0 and 1 when `checker`, else smooth colours).
struct Image {
  std::uint32_t side;
  bool checker;
  Vec3 at(std::uint32_t x, std::uint32_t y) const {
    if (checker) return Vec3(static_cast<float>((x + y) % 2));
    const float fx = static_cast<float>(x) / static_cast<float>(side), fy = static_cast<float>(y) / static_cast<float>(side);
    return Vec3(fx, fy, 0.5f + 0.5f * std::sin(7.0f * fx + 3.0f * fy));
  }
  std::vector<float> rgba() const {
    std::vector<float> out;
    for (std::uint32_t y = 0; y < side; ++y) {
      for (std::uint32_t x = 0; x < side; ++x) {
        const Vec3 c = at(x, y);
        out.insert(out.end(), {c.x, c.y, c.z, 1.0f});
      }
    }
    return out;
  }
  // Bilinear, repeating, in double: texel centres at (i + 0.5) / side.
  double sample(double u, double v, int c) const {
    const double n = side;
    const double x = (u - std::floor(u)) * n - 0.5, y = (v - std::floor(v)) * n - 0.5;
    const double x0 = std::floor(x), y0 = std::floor(y);
    double out = 0.0;
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const auto xi = static_cast<std::uint32_t>(std::fmod(x0 + dx + n, n));
        const auto yi = static_cast<std::uint32_t>(std::fmod(y0 + dy + n, n));
        const double w = (dx ? x - x0 : 1.0 - (x - x0)) * (dy ? y - y0 : 1.0 - (y - y0));
        out += w * static_cast<double>(at(xi, yi)[c]);
      }
    }
    return out;
  }
};

// The mannequin with one white material textured by `image`, its uvs a
// planar projection of its bind pose along z, baked over its idle clip.
testing_support::BakedModel textured_mannequin(const Image& image) {
  character::Model model = content::make_mannequin().value();
  SkinnedMesh& mesh = model.mesh;
  mesh.uvs.clear();
  for (const Vec3& p : mesh.positions) mesh.uvs.emplace_back(1.3f * p.x + 0.5f, 1.0f - 0.9f * p.y);
  mesh.triangle_material.assign(mesh.triangle_count(), 0);
  mesh.material_colors = {Vec3(1.0f)};
  model.material_names = {"textured"};
  mesh.material_texture = {0};
  mesh.textures = {make_texture("image", image.side, image.side, image.rgba(), TextureWrap::kRepeat,
                                TextureWrap::kRepeat)
                       .value()};
  return testing_support::bake_over_idle(std::move(model));
}

// Renders the model's albedo (ambient 1, no light) from `eye`.
struct Rendered {
  std::unique_ptr<rt::Scene> scene;
  rt::PinholeCamera camera;
  testing_support::AovFrame frame;
};
Rendered render_albedo(const testing_support::BakedModel& m, const Vec3& eye, int size) {
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene->add_instance(character).value();
  EXPECT_TRUE(scene->set_bones(instance, testing_support::clip_pose(m.model, "idle", 0.3)).ok());
  JobSystem jobs(2);
  EXPECT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  const auto camera = rt::PinholeCamera::create({eye, Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 40.0f}, size, size).value();
  testing_support::AovFrame frame(size, size);
  rt::RenderSettings settings;
  settings.ambient = Vec3(1.0f);
  settings.shadows = false;
  // The settings' default light, made dark: the colour is the albedo.
  static rt::Light dark[1];
  dark[0].color = Vec3(0.0f);
  settings.lights = dark;
  rt::Renderer renderer;
  EXPECT_TRUE(renderer.render(*scene, camera, settings, frame.buffers(), jobs).ok());
  return {std::move(scene), camera, std::move(frame)};
}

TEST(TexturedRender, MagnifiedTexelsMatchABilinearLookupOfTheSourceImageAtTheBruteForceHitsUv) {
  const Image image{8, false};
  const testing_support::BakedModel m = textured_mannequin(image);
  const Rendered r = render_albedo(m, Vec3(0.3f, 1.1f, 2.6f), 96);
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(*r.scene);
  const SkinnedMesh& mesh = m.model.mesh;
  int checked = 0;
  float lo = 1.0f, hi = 0.0f;
  for (int y = 0; y < r.frame.height; ++y) {
    for (int x = 0; x < r.frame.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * r.frame.width + x);
      if (r.frame.instance_id[p] == kInvalidId) continue;
      const Ray ray = r.camera.ray(x, y);
      const Hit hit = testing_support::nearest(soup, ray, rt::TriangleTest::kFast);
      ASSERT_TRUE(hit.valid());
      if (hit.triangle_id != r.frame.triangle_id[p]) continue;  // an edge: the tests' rounding differs
      const auto& v = mesh.triangles[hit.triangle_id];
      const auto& tri = soup[hit.triangle_id];
      const Vec3 g = glm::normalize(glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
      // Away from grazing angles a pixel covers well under a texel of this
      // 8x8 image: level 0, no mip transition.
      if (std::fabs(glm::dot(g, glm::normalize(ray.direction))) < 0.5f) continue;
      const double b1 = hit.u, b2 = hit.v, b0 = 1.0 - b1 - b2;
      const auto interpolate = [&](int a) {
        return b0 * static_cast<double>(mesh.uvs[v[0]][a]) + b1 * static_cast<double>(mesh.uvs[v[1]][a]) +
               b2 * static_cast<double>(mesh.uvs[v[2]][a]);
      };
      const double u = interpolate(0), vv = interpolate(1);
      for (int c = 0; c < 3; ++c) {
        const float got = r.frame.rgba32f[4 * p + static_cast<std::size_t>(c)];
        ASSERT_NEAR(got, image.sample(u, vv, c), 1.0 / 255.0) << "pixel " << x << "," << y << " channel " << c << " uv " << u << " " << vv << " t " << hit.t << " tri " << hit.triangle_id;
        lo = std::min(lo, got);
        hi = std::max(hi, got);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(hi - lo, 0.5f) << "the texture varies across the character";
}

TEST(TexturedRender, AOneTexelCheckerboardSeenFromFarAwayAveragesToGreyThroughTheMipChain) {
  const Image image{256, true};
  const testing_support::BakedModel m = textured_mannequin(image);
  const Rendered r = render_albedo(m, Vec3(0.0f, 1.0f, 11.0f), 192);
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(*r.scene);
  int checked = 0;
  for (int y = 0; y < r.frame.height; ++y) {
    for (int x = 0; x < r.frame.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * r.frame.width + x);
      if (r.frame.instance_id[p] == kInvalidId) continue;
      const auto& tri = soup[r.frame.triangle_id[p]];
      const Vec3 g = glm::normalize(glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
      // Where the planar projection squeezes the uvs (sides facing x or y),
      // a pixel covers few texels and level 0 is right: only the faces
      // toward the projection are asked to average.
      if (std::fabs(g.z) < 0.7f) continue;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(r.frame.rgba32f[4 * p + static_cast<std::size_t>(c)], 0.5f, 0.01f) << "pixel " << x << "," << y;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(TexturedRender, WithoutTheTextureTheSameRenderIsTheMaterialColour) {
  const Image image{8, false};
  testing_support::BakedModel m = textured_mannequin(image);
  m.model.mesh.material_texture = {kNoTexture};
  m.model.mesh.material_colors = {Vec3(0.25f, 0.5f, 0.75f)};
  const Rendered r = render_albedo(m, Vec3(0.3f, 1.1f, 2.6f), 48);
  int hits = 0;
  for (std::size_t p = 0; p < r.frame.instance_id.size(); ++p) {
    if (r.frame.instance_id[p] == kInvalidId) continue;
    ++hits;
    EXPECT_EQ(r.frame.rgba32f[4 * p], 0.25f);
    EXPECT_EQ(r.frame.rgba32f[4 * p + 1], 0.5f);
    EXPECT_EQ(r.frame.rgba32f[4 * p + 2], 0.75f);
  }
  EXPECT_GT(hits, 100);
}

TEST(TexturedRender, HitAttributeOutputsAreTheBruteForceHitsBarycentricsUvAndMaterial) {
  const Image image{8, false};
  testing_support::BakedModel m = textured_mannequin(image);
  // Four materials, so the ids mean something; the ground has none.
  SkinnedMesh& mesh = m.model.mesh;
  mesh.material_colors = {Vec3(1.0f), Vec3(0.5f), Vec3(0.25f), Vec3(0.75f)};
  mesh.material_texture = {0, kNoTexture, 0, kNoTexture};
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) mesh.triangle_material[t] = static_cast<std::uint32_t>(t % 4);
  auto scene = std::make_unique<rt::Scene>();
  const std::uint32_t character = scene->add_character(mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene->add_instance(character).value();
  ASSERT_TRUE(scene->set_bones(instance, testing_support::clip_pose(m.model, "idle", 0.7)).ok());
  rt::StaticMeshDesc ground;
  ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  ASSERT_TRUE(scene->add_static_mesh(ground).ok());
  JobSystem jobs(2);
  ASSERT_TRUE(scene->prepare_frame(rt::FrameOptions{}, jobs).ok());
  const int size = 80;
  const auto camera =
      rt::PinholeCamera::create({Vec3(0.8f, 1.6f, 2.8f), Vec3(0.0f, 0.8f, 0.0f), Vec3(0, 1, 0), 45.0f}, size, size)
          .value();
  std::vector<Vec2> uv(size * size), barycentric(size * size);
  std::vector<std::uint32_t> material(size * size), triangle(size * size), object(size * size);
  // Without and with the id outputs: the attributes alone must be the same.
  std::vector<Vec2> uv_alone;
  std::vector<std::uint32_t> material_alone;
  for (int round = 0; round < 2; ++round) {
    rt::FrameBuffers buffers;
    buffers.width = buffers.height = size;
    buffers.uv = uv;
    buffers.barycentric = barycentric;
    buffers.material_id = material;
    if (round == 1) {
      buffers.triangle_id = triangle;
      buffers.instance_id = object;
    }
    std::fill(uv.begin(), uv.end(), Vec2(-7.0f));
    std::fill(material.begin(), material.end(), 12345u);
    rt::Renderer renderer;
    ASSERT_TRUE(renderer.render(*scene, camera, rt::RenderSettings{}, buffers, jobs).ok());
    if (round == 0) {
      uv_alone = uv;
      material_alone = material;
    }
  }
  EXPECT_EQ(uv_alone, uv);
  EXPECT_EQ(material_alone, material);
  const std::vector<testing_support::SoupTriangle> soup = testing_support::world_triangles(*scene);
  int on_character = 0, on_ground = 0, missed = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * size + x);
      const Hit hit = testing_support::nearest(soup, camera.ray(x, y), rt::TriangleTest::kFast);
      if (object[p] == kInvalidId) {
        ASSERT_FALSE(hit.valid());
        EXPECT_EQ(uv[p], Vec2(0.0f));
        EXPECT_EQ(barycentric[p], Vec2(0.0f));
        EXPECT_EQ(material[p], kInvalidId);
        ++missed;
        continue;
      }
      if (!hit.valid() || hit.triangle_id != triangle[p] || hit.instance_id != object[p]) continue;  // an edge
      EXPECT_NEAR(barycentric[p].x, hit.u, 1e-4f);
      EXPECT_NEAR(barycentric[p].y, hit.v, 1e-4f);
      if (object[p] != instance) {  // the ground: no materials of its own, no uvs
        EXPECT_EQ(material[p], kInvalidId);
        EXPECT_EQ(uv[p], Vec2(0.0f));
        ++on_ground;
        continue;
      }
      EXPECT_EQ(material[p], hit.triangle_id % 4);
      const auto& v = mesh.triangles[hit.triangle_id];
      const float w = 1.0f - hit.u - hit.v;
      for (int a = 0; a < 2; ++a) {
        EXPECT_NEAR(uv[p][a], w * mesh.uvs[v[0]][a] + hit.u * mesh.uvs[v[1]][a] + hit.v * mesh.uvs[v[2]][a], 1e-4f);
      }
      ++on_character;
    }
  }
  EXPECT_GT(on_character, 300);
  EXPECT_GT(on_ground, 300);
  EXPECT_GT(missed, 100);
}

}  // namespace
}  // namespace sinew
