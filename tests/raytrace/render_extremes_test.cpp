// Beyond the sampled pose space and at numerical extremes (docs/DESIGN.md
// sections 4 and 5): escapes are detected and the fallback keeps every ray
// exact; scales 1e-3 and 1e4, a character 1e5 units from the origin,
// axis-parallel rays, origins on split planes, zero-area triangles and
// zero-scale bones all match brute force. Also the renderer: its AOVs are
// the traversal's hits, and images are identical for 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "animation/pose_space.h"
#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/packet_traversal.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/brute_force.h"
#include "tests/support/idle_mannequin.h"

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::SoupTriangle;

constexpr TriangleTest kTests[] = {TriangleTest::kFast, TriangleTest::kWatertight};

float unit(std::mt19937_64& g) { return anim::unit_float(g()); }

// The mannequin baked over one clip's keys: small and quick, and posing it
// with another clip leaves that pose space.
using Mannequin = testing_support::BakedModel;
using testing_support::idle_mannequin;


std::vector<Affine3> pose(const character::Model& model, const std::string& clip, double t,
                          const Affine3& instance = Affine3::identity()) {
  return testing_support::clip_pose(model, clip, t, instance);
}

struct Checked {
  std::size_t rays = 0;
  std::size_t wrong = 0;
  std::string first;
};

void check_ray(const rt::Scene& scene, std::span<const SoupTriangle> soup, const Ray& ray, Checked& c) {
  for (const TriangleTest test : kTests) {
    const Hit ours = rt::intersect(scene, ray, test);
    const Hit ref = testing_support::nearest(soup, ray, test);
    ++c.rays;
    const bool ok = testing_support::same_nearest(ours, ref, soup, ray, test) &&
                    rt::occluded(scene, ray, test) == ref.valid();
    if (!ok && c.wrong++ == 0) {
      c.first = "ray (" + std::to_string(ray.origin.x) + "," + std::to_string(ray.origin.y) + "," +
                std::to_string(ray.origin.z) + ") dir (" + std::to_string(ray.direction.x) + "," +
                std::to_string(ray.direction.y) + "," + std::to_string(ray.direction.z) + "): ours t=" +
                std::to_string(ours.t) + " tri " + std::to_string(ours.triangle_id) + ", ref t=" +
                std::to_string(ref.t) + " tri " + std::to_string(ref.triangle_id);
    }
  }
}

// Rays at the character from all around plus rays from inside it, half of
// them aimed at triangle points, some axis-parallel.
Checked check_scene(const rt::Scene& scene, std::size_t count, std::uint64_t seed) {
  const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
  Aabb box;
  for (const Vec3& p : scene.instances()[0].positions) box.extend(p);
  const Vec3 c = box.center();
  const Vec3 e = box.extent();
  std::mt19937_64 g(seed);
  Checked checked;
  for (std::size_t i = 0; i < count; ++i) {
    Ray ray;
    ray.origin = c + Vec3(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f) * e * 1.6f;
    if (i % 3 == 0) {
      ray.direction = Vec3(0.0f);
      ray.direction[static_cast<int>(i / 3 % 3)] = (i % 2) ? 1.0f : -1.0f;
    } else {
      const SoupTriangle& tri = soup[g() % soup.size()];
      const float u = unit(g);
      const float v = unit(g) * (1.0f - u);
      ray.direction = (1.0f - u - v) * tri.p0 + u * tri.p1 + v * tri.p2 - ray.origin;
      if (ray.direction == Vec3(0.0f)) ray.direction = Vec3(0.0f, 0.0f, 1.0f);
    }
    check_ray(scene, soup, ray, checked);
  }
  return checked;
}

rt::Scene scene_with(const Mannequin& m, std::span<const Affine3> bones, const rt::FrameOptions& options,
                     rt::FrameStats* stats_out = nullptr) {
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene.add_instance(character).value();
  EXPECT_TRUE(scene.set_bones(instance, bones).ok());
  JobSystem jobs(2);
  auto stats = scene.prepare_frame(options, jobs);
  EXPECT_TRUE(stats.ok()) << stats.status().message();
  if (stats_out && stats.ok()) *stats_out = *stats;
  return scene;
}

TEST(RenderEscapes, PosesOutsideThePoseSpaceAreCountedAndTheFallbackKeepsRaysExact) {
  const Mannequin& m = idle_mannequin();
  const std::vector<Affine3> kick = pose(m.model, "kick", 0.4);
  rt::FrameStats stats;
  const rt::Scene scene = scene_with(m, kick, rt::FrameOptions{}, &stats);
  EXPECT_GT(stats.escaped_checks, 0u) << "a kick is not an idle pose: vertices must escape";
  EXPECT_GT(stats.escaped_triangles, 0u);
  const Checked checked = check_scene(scene, 4000, 7);
  EXPECT_EQ(checked.wrong, 0u) << checked.rays << " rays; first: " << checked.first;
  RecordProperty("escaped_triangles", static_cast<int>(stats.escaped_triangles));
}

TEST(RenderEscapes, WithoutTheFallbackEscapesAreStillCounted) {
  const Mannequin& m = idle_mannequin();
  rt::FrameOptions options;
  options.fallback = false;
  rt::FrameStats stats;
  const rt::Scene scene = scene_with(m, pose(m.model, "kick", 0.4), options, &stats);
  EXPECT_GT(stats.escaped_checks, 0u);
  EXPECT_EQ(stats.escaped_triangles, 0u) << "no fallback: nothing is routed";
  // Holes are allowed here; how many is a benchmark figure, not a test.
  const Checked checked = check_scene(scene, 2000, 8);
  RecordProperty("wrong_rays_without_fallback", static_cast<int>(checked.wrong));
}

TEST(RenderEscapes, ASampledPoseHasNoEscapes) {
  const Mannequin& m = idle_mannequin();
  rt::FrameStats stats;
  const rt::Scene scene = scene_with(m, pose(m.model, "idle", 0.0), rt::FrameOptions{}, &stats);
  EXPECT_EQ(stats.escaped_checks, 0u);
  EXPECT_EQ(stats.escaped_triangles, 0u);
}

struct Placement {
  const char* name;
  float scale;
  Vec3 offset;
};

class RenderExtremes : public ::testing::TestWithParam<Placement> {};

TEST_P(RenderExtremes, ScaledAndDistantCharactersMatchBruteForce) {
  const Placement p = GetParam();
  const Mannequin& m = idle_mannequin();
  const Affine3 instance = Affine3::from_trs(p.offset, Quat(1.0f, 0.0f, 0.0f, 0.0f), Vec3(p.scale));
  for (const rt::BoneBoxMode boxes : {rt::BoneBoxMode::kExact, rt::BoneBoxMode::kCheap}) {
    rt::FrameOptions options;
    options.bone_boxes = boxes;
    rt::FrameStats stats;
    const rt::Scene scene = scene_with(m, pose(m.model, "idle", 1.3, instance), options, &stats);
    // Far from the origin float spacing is ~1 cm, so the traversal's
    // rounding slack covers most of a bone's tree: correct but slow, so
    // fewer rays there.
    const Checked checked = check_scene(scene, p.offset == Vec3(0.0f) ? 3000 : 500, 11);
    EXPECT_EQ(checked.wrong, 0u) << p.name << (boxes == rt::BoneBoxMode::kExact ? " exact" : " cheap")
                                 << " boxes: " << checked.rays << " rays; first: " << checked.first;
    RecordProperty(std::string(p.name) + "_escaped_checks", static_cast<int>(stats.escaped_checks));
  }
}

INSTANTIATE_TEST_SUITE_P(Placements, RenderExtremes,
                         ::testing::Values(Placement{"unit", 1.0f, Vec3(0.0f)},
                                           Placement{"millimetre", 1e-3f, Vec3(0.0f)},
                                           Placement{"huge", 1e4f, Vec3(0.0f)},
                                           Placement{"far", 1.0f, Vec3(1e5f, -3e4f, 7e4f)}),
                         [](const ::testing::TestParamInfo<Placement>& param) { return std::string(param.param.name); });

TEST(RenderExtremes, ZeroScaleBonesGoThroughTheFallback) {
  const Mannequin& m = idle_mannequin();
  std::vector<Affine3> bones = pose(m.model, "idle", 0.5);
  const auto lowerarm = m.model.skeleton.find("lowerarm_l");
  ASSERT_TRUE(lowerarm.has_value());
  // Collapse the forearm onto its joint: the skinning matrix loses all scale.
  Affine3& b = bones[static_cast<std::size_t>(*lowerarm)];
  const Vec3 keep = b.transform_point(m.model.mesh.positions[0]);
  for (Vec4& row : b.rows) row = Vec4(0.0f, 0.0f, 0.0f, 0.0f);
  b.rows[0].w = keep.x;
  b.rows[1].w = keep.y;
  b.rows[2].w = keep.z;
  rt::FrameStats stats;
  const rt::Scene scene = scene_with(m, bones, rt::FrameOptions{}, &stats);
  EXPECT_EQ(stats.singular_bones, 1u);
  EXPECT_GT(stats.escaped_triangles, 0u);
  const Checked checked = check_scene(scene, 3000, 12);
  EXPECT_EQ(checked.wrong, 0u) << checked.rays << " rays; first: " << checked.first;
}

TEST(RenderExtremes, ZeroAreaTrianglesNeverHitAndDoNotDisturbTheirNeighbours) {
  Mannequin m;
  m.model = content::make_mannequin().value();
  // Collapse every 17th triangle to a segment (a repeated corner) and a
  // few to a point.
  for (std::size_t t = 0; t < m.model.mesh.triangles.size(); t += 17) {
    auto& tri = m.model.mesh.triangles[t];
    tri[2] = tri[1];
    if (t % 5 == 0) tri[1] = tri[0];
  }
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {"walk"};
  request.pose_space.samples = 0;
  JobSystem jobs(2);
  m.bake = character::bake_in_memory(m.model, request, jobs).value();
  const rt::Scene scene = scene_with(m, pose(m.model, "walk", 0.2), rt::FrameOptions{});
  const Checked checked = check_scene(scene, 3000, 13);
  EXPECT_EQ(checked.wrong, 0u) << checked.rays << " rays; first: " << checked.first;
}

TEST(RenderExtremes, OriginsOnSplitPlanes) {
  const Mannequin& m = idle_mannequin();
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  const std::uint32_t instance = scene.add_instance(character).value();
  // A ground grid whose kd-tree splits lie on exact floats.
  rt::StaticMeshDesc ground;
  for (int z = 0; z <= 8; ++z) {
    for (int x = 0; x <= 8; ++x) ground.positions.push_back(Vec3(-2.0f + 0.5f * x, 0.0f, -2.0f + 0.5f * z));
  }
  for (std::uint32_t z = 0; z < 8; ++z) {
    for (std::uint32_t x = 0; x < 8; ++x) {
      const std::uint32_t i = z * 9 + x;
      ground.triangles.push_back({i, i + 9, i + 1});
      ground.triangles.push_back({i + 1, i + 9, i + 10});
    }
  }
  ASSERT_TRUE(scene.add_static_mesh(ground).ok());
  ASSERT_TRUE(scene.set_bones(instance, pose(m.model, "idle", 0.0)).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);

  // Collect split planes of the static tree and of the bone trees (in world
  // space for the bone at the rest pose, where bone frames are model space).
  std::vector<std::pair<int, float>> planes;
  for (const rt::KdNode& node : scene.static_meshes()[0].tree.nodes) {
    if (!node.is_leaf()) planes.emplace_back(node.axis(), node.split());
  }
  const rt::FuzzyCharacterView fuzzy = m.bake.fuzzy.view();
  for (const rt::KdNode& node : fuzzy.nodes) {
    if (!node.is_leaf() && planes.size() < 400) planes.emplace_back(node.axis(), node.split());
  }
  ASSERT_GT(planes.size(), 10u);
  std::mt19937_64 g(21);
  Checked checked;
  for (const auto& [axis, split] : planes) {
    for (int k = 0; k < 4; ++k) {
      Ray ray;
      ray.origin = Vec3(unit(g) * 2.0f - 1.0f, unit(g) * 2.0f, unit(g) * 2.0f - 1.0f);
      ray.origin[axis] = split;
      // In the plane, across it, and along each axis.
      Vec3 d(unit(g) - 0.5f, unit(g) - 0.5f, unit(g) - 0.5f);
      if (k == 0) d[axis] = 0.0f;
      if (k >= 2) {
        d = Vec3(0.0f);
        d[(axis + k - 1) % 3] = (k == 2) ? 1.0f : -1.0f;
      }
      if (d == Vec3(0.0f)) d = Vec3(0.0f, -1.0f, 0.0f);
      ray.direction = d;
      check_ray(scene, soup, ray, checked);
    }
  }
  EXPECT_EQ(checked.wrong, 0u) << checked.rays << " rays; first: " << checked.first;
}

TEST(Renderer, AovsAreTheTraversalsHitsAndImagesDoNotDependOnThreads) {
  const Mannequin& m = idle_mannequin();
  rt::Scene scene;
  const std::uint32_t character = scene.add_character(m.model.mesh, m.bake.fuzzy.view()).value();
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t instance = scene.add_instance(character).value();
    const Affine3 place = Affine3::translation(Vec3(0.9f * static_cast<float>(i) - 0.45f, 0.0f, 0.0f));
    ASSERT_TRUE(scene.set_bones(instance, pose(m.model, "idle", 0.7 * i, place)).ok());
  }
  rt::StaticMeshDesc ground;
  ground.positions = {{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}, {5, 0, 5}};
  ground.triangles = {{0, 2, 1}, {1, 2, 3}};
  ASSERT_TRUE(scene.add_static_mesh(ground).ok());
  JobSystem one(1), two(2);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, two).ok());
  const int w = 96, h = 80;
  const auto camera = rt::PinholeCamera::create({Vec3(0.5f, 1.4f, 3.0f), Vec3(0.0f, 0.9f, 0.0f), Vec3(0, 1, 0), 45.0f}, w, h);
  ASSERT_TRUE(camera.ok());
  struct Images {
    std::vector<std::uint8_t> color;
    std::vector<float> depth;
    std::vector<Vec3> normal;
    std::vector<std::uint32_t> triangle, instance;
  };
  const auto render = [&](JobSystem& jobs, TriangleTest test, int packet_rays = 64) {
    Images im;
    const std::size_t n = static_cast<std::size_t>(w * h);
    im.color.resize(4 * n);
    im.depth.resize(n);
    im.normal.resize(n);
    im.triangle.resize(n);
    im.instance.resize(n);
    rt::FrameBuffers buffers{w, h, im.color, {}, im.depth, im.normal, im.triangle, im.instance, {}, {}, {}, {}, {}, {}};
    rt::RenderSettings settings;
    settings.triangle_test = test;
    settings.packet_rays = packet_rays;
    rt::Renderer renderer;
    auto stats = renderer.render(scene, *camera, settings, buffers, jobs);
    EXPECT_TRUE(stats.ok()) << stats.status().message();
    if (stats.ok()) {
      EXPECT_EQ(stats->primary_rays, n);
      EXPECT_GT(stats->shadow_rays, 0u);
      EXPECT_GT(stats->shadowed, 0u) << "the characters shadow the ground";
    }
    return im;
  };
  for (const TriangleTest test : kTests) {
    const Images a = render(one, test);
    const Images b = render(two, test);
    EXPECT_EQ(a.color, b.color);
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.triangle, b.triangle);
    EXPECT_EQ(a.instance, b.instance);
    // Packets of every size and single rays give the same image.
    for (const int packet_rays : {1, 8, 256}) {
      const Images c = render(two, test, packet_rays);
      EXPECT_EQ(a.color, c.color) << packet_rays;
      EXPECT_EQ(a.depth, c.depth) << packet_rays;
      EXPECT_EQ(a.triangle, c.triangle) << packet_rays;
    }
    std::size_t character_pixels = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * w + x);
        const Ray ray = camera->ray(x, y);
        const Hit hit = rt::intersect(scene, ray, test);
        ASSERT_EQ(a.triangle[i], hit.triangle_id) << x << "," << y;
        ASSERT_EQ(a.instance[i], hit.instance_id) << x << "," << y;
        if (hit.valid()) {
          EXPECT_EQ(a.depth[i], hit.t * glm::length(ray.direction));
          EXPECT_NEAR(glm::length(a.normal[i]), 1.0f, 1e-4f);
          // Shading normals lie on the camera's side of the surface.
          Vec3 facing = rt::surface_at(scene, hit, Vec3(1.0f)).geometric_normal;
          if (glm::dot(facing, ray.direction) > 0.0f) facing = -facing;
          EXPECT_GE(glm::dot(a.normal[i], facing), 0.0f) << x << "," << y;
          character_pixels += hit.instance_id < 2 ? 1 : 0;
        } else {
          EXPECT_TRUE(std::isinf(a.depth[i]));
        }
      }
    }
    EXPECT_GT(character_pixels, 500u);
  }
}

TEST(Renderer, RejectsMismatchedBuffers) {
  rt::Scene scene;
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  const auto camera = rt::PinholeCamera::create({}, 8, 8);
  ASSERT_TRUE(camera.ok());
  std::vector<float> depth(10);
  rt::FrameBuffers buffers;
  buffers.width = 8;
  buffers.height = 8;
  buffers.depth = depth;
  rt::Renderer renderer;
  auto stats = renderer.render(scene, *camera, {}, buffers, jobs);
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.status().field(), "buffers.depth");
}

}  // namespace
}  // namespace sinew

namespace sinew {
namespace {

// A floor and a box floating above it in ONE static mesh: a shadow ray from
// the floor under the box toward a light above must be blocked by the
// box's own triangles (the demo arena's case: floor and obstacles share a
// mesh), for single rays and packets, both triangle tests.
TEST(RenderStatic, AStaticMeshShadowsItself) {
  rt::StaticMeshDesc mesh;
  const auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, c, d});
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.triangles.push_back({base, base + 2, base + 3});
  };
  // Floor tiles of 2 m over [-8, 8]^2, so the mesh has a real kd-tree.
  for (int j = 0; j < 8; ++j) {
    for (int i = 0; i < 8; ++i) {
      const float x = -8.0f + 2.0f * static_cast<float>(i), z = -8.0f + 2.0f * static_cast<float>(j);
      quad(Vec3(x, 0, z), Vec3(x, 0, z + 2), Vec3(x + 2, 0, z + 2), Vec3(x + 2, 0, z));
    }
  }
  // The box's bottom face at y = 2 over [-1, 1]^2 (enough to block).
  quad(Vec3(-1, 2, -1), Vec3(1, 2, -1), Vec3(1, 2, 1), Vec3(-1, 2, 1));
  rt::Scene scene;
  ASSERT_TRUE(scene.add_static_mesh(mesh).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  for (const TriangleTest test : {TriangleTest::kFast, TriangleTest::kWatertight}) {
    rt::RayPacket packet;
    for (int lane = 0; lane < rt::kPacketSize; ++lane) {
      Ray shadow;
      shadow.origin = Vec3(-0.5f + 0.1f * static_cast<float>(lane), 1e-4f, 0.3f);
      shadow.direction = Vec3(0.0f, 10.0f, 0.0f) - shadow.origin;  // a point light at (0, 10, 0)
      shadow.t_min = 0.0f;
      shadow.t_max = 1.0f;
      EXPECT_TRUE(rt::occluded(scene, shadow, test)) << "lane " << lane;
      packet.set(lane, shadow);
    }
    EXPECT_EQ(rt::occluded_packet(scene, packet, test), 0xFF);
    // Beside the box the light is visible.
    Ray free;
    free.origin = Vec3(4.0f, 1e-4f, 4.0f);
    free.direction = Vec3(0.0f, 10.0f, 0.0f) - free.origin;
    free.t_max = 1.0f;
    EXPECT_FALSE(rt::occluded(scene, free, test));
  }
}

}  // namespace
}  // namespace sinew

namespace sinew {
namespace {

// Renders a colour image of `camera` lit by a point light at `light`; the
// render's stats.
rt::RenderStats render_lit(const rt::Scene& scene, const rt::PinholeCamera& camera, const Vec3& light,
                           int packet_rays, TriangleTest test, JobSystem& jobs) {
  rt::RenderSettings settings;
  settings.light.position = light;
  settings.packet_rays = packet_rays;
  settings.triangle_test = test;
  std::vector<std::uint8_t> color(static_cast<std::size_t>(camera.width()) * camera.height() * 4);
  rt::FrameBuffers buffers;
  buffers.width = camera.width();
  buffers.height = camera.height();
  buffers.color_rgba8 = color;
  rt::Renderer renderer;
  auto stats = renderer.render(scene, camera, settings, buffers, jobs);
  EXPECT_TRUE(stats.ok());
  return stats.ok() ? *stats : rt::RenderStats{};
}

// A floor at exactly y = 0 under a light, nothing in between: no pixel may
// be shadowed (a shadow ray must not hit the floor it ends on). Before the
// shadow offset accounted for the triangle test's own rounding, a floor at
// y = 0 had a zero error bound and shadowed itself everywhere. Lights near
// the floor (grazing rays) and thousands of floor sizes away (rays from the
// light round at its magnitude) too.
// A 32 x 32 floor of sixteen quads at exactly y = 0, centred on the origin.
rt::StaticMeshDesc floor_at_zero() {
  rt::StaticMeshDesc floor;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      const float x = -16.0f + 8.0f * static_cast<float>(i), z = -16.0f + 8.0f * static_cast<float>(j);
      const auto base = static_cast<std::uint32_t>(floor.positions.size());
      floor.positions.insert(floor.positions.end(),
                             {Vec3(x, 0, z), Vec3(x, 0, z + 8), Vec3(x + 8, 0, z + 8), Vec3(x + 8, 0, z)});
      floor.triangles.push_back({base, base + 1, base + 2});
      floor.triangles.push_back({base, base + 2, base + 3});
    }
  }
  return floor;
}

TEST(RenderStatic, AFloorAtExactlyZeroDoesNotShadowItself) {
  rt::Scene scene;
  ASSERT_TRUE(scene.add_static_mesh(floor_at_zero()).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  rt::CameraDesc desc;
  desc.eye = Vec3(0.0f, 6.0f, -12.0f);
  desc.target = Vec3(0.0f, 0.0f, 0.0f);
  auto camera = rt::PinholeCamera::create(desc, 64, 64);
  ASSERT_TRUE(camera.ok());
  for (const Vec3& light : {Vec3(6.0f, 12.0f, 4.0f), Vec3(0.5f, 0.25f, 0.5f), Vec3(3e4f, 6e4f, -2e4f)}) {
    for (const int packet_rays : {1, 8, 64, 256, 512}) {
      const rt::RenderStats stats = render_lit(scene, *camera, light, packet_rays, TriangleTest::kFast, jobs);
      EXPECT_GT(stats.shadow_rays, 1000u);
      EXPECT_EQ(stats.shadowed, 0u) << packet_rays << " rays per packet, light y " << light.y;
    }
  }
}

// The colour outputs against the shading model computed here in double:
// ambient plus the light's colour times N.L (the floor faces +y), times the
// albedo, and for RGBA8 the sRGB curve of IEC 61966-2-1 rounded to a byte;
// misses get the background. Dim and overbright settings cover the curve's
// linear toe and the clamp at 1.
TEST(RenderStatic, ColoursFollowTheShadingModelAndTheSrgbCurve) {
  rt::Scene scene;
  ASSERT_TRUE(scene.add_static_mesh(floor_at_zero()).ok());
  JobSystem jobs(2);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  rt::CameraDesc desc;
  desc.eye = Vec3(0.0f, 6.0f, -12.0f);
  desc.target = Vec3(0.0f, 0.0f, 4.0f);
  constexpr int kSize = 80;
  auto camera = rt::PinholeCamera::create(desc, kSize, kSize);
  ASSERT_TRUE(camera.ok());
  const auto srgb = [](double linear) {
    const double c = std::clamp(linear, 0.0, 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  };
  struct Case {
    Vec3 ambient, light_color, albedo, light;
  };
  const Case cases[] = {
      {Vec3(0.18f), Vec3(1.0f), Vec3(0.7f), Vec3(6.0f, 12.0f, 4.0f)},
      {Vec3(0.0f), Vec3(0.004f, 0.02f, 0.09f), Vec3(0.5f, 0.9f, 0.2f), Vec3(-3.0f, 2.0f, 9.0f)},
      {Vec3(0.3f, 0.1f, 0.0f), Vec3(3.0f, 1.2f, 0.6f), Vec3(0.9f), Vec3(0.5f, 0.25f, 0.5f)},
      {Vec3(0.05f), Vec3(1.0f), Vec3(0.7f), Vec3(2.0f, -5.0f, 1.0f)},  // below: ambient only
  };
  const auto pixels = static_cast<std::size_t>(kSize) * kSize;
  std::size_t lit = 0, toe = 0, clamped = 0;
  for (const Case& c : cases) {
    for (const int packet_rays : {1, 256}) {
      rt::RenderSettings settings;
      settings.light.position = c.light;
      settings.light.color = c.light_color;
      settings.ambient = c.ambient;
      settings.default_albedo = c.albedo;
      settings.packet_rays = packet_rays;
      std::vector<std::uint8_t> rgba8(4 * pixels);
      std::vector<float> rgba32f(4 * pixels), depth(pixels);
      rt::FrameBuffers buffers;
      buffers.width = buffers.height = kSize;
      buffers.color_rgba8 = rgba8;
      buffers.color_rgba32f = rgba32f;
      buffers.depth = depth;
      rt::Renderer renderer;
      ASSERT_TRUE(renderer.render(scene, *camera, settings, buffers, jobs).ok());
      for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * kSize + static_cast<std::size_t>(x);
          double expected[3];
          if (std::isinf(depth[i])) {
            for (int a = 0; a < 3; ++a) expected[a] = settings.background[a];
          } else {
            const Ray ray = camera->ray(x, y);
            const glm::dvec3 dir = glm::normalize(glm::dvec3(ray.direction));
            const glm::dvec3 p = glm::dvec3(ray.origin) + static_cast<double>(depth[i]) * dir;
            const glm::dvec3 to_light = glm::dvec3(c.light) - p;
            const double cosine = std::max(0.0, to_light.y / glm::length(to_light));
            if (cosine > 0.0) ++lit;
            for (int a = 0; a < 3; ++a) {
              expected[a] = static_cast<double>(c.albedo[a]) *
                            (static_cast<double>(c.ambient[a]) + static_cast<double>(c.light_color[a]) * cosine);
              if (expected[a] > 0.0 && expected[a] <= 0.0031308) ++toe;
              if (expected[a] > 1.0) ++clamped;
            }
          }
          for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(rgba32f[4 * i + a], expected[a], 1e-5 + 1e-5 * expected[a]) << x << "," << y << " channel " << a;
            EXPECT_NEAR(rgba8[4 * i + a], std::lround(255.0 * srgb(expected[a])), 1) << x << "," << y << " channel " << a;
          }
          EXPECT_EQ(rgba8[4 * i + 3], 255);
          EXPECT_EQ(rgba32f[4 * i + 3], 1.0f);
        }
      }
    }
  }
  EXPECT_GT(lit, pixels);  // the cases reach every part of the curve
  EXPECT_GT(toe, 100u);
  EXPECT_GT(clamped, 100u);
}

// The same on a tilted floor away from the origin, where no coordinate is
// exact: rays from the light round at its magnitude and length, and the
// shadow ray's end must clear the floor by that much (shadow_ray_from_light).
TEST(RenderStatic, ATiltedFloorDoesNotShadowItselfUnderNearAndFarLights) {
  const Vec3 centre(310.7f, -42.3f, 127.9f);
  const Vec3 u = glm::normalize(Vec3(0.83f, 0.31f, -0.12f));
  const Vec3 v = glm::normalize(glm::cross(Vec3(0.2f, 0.1f, 1.0f), u));
  const Vec3 up = glm::cross(u, v);
  rt::StaticMeshDesc floor;
  constexpr int kQuads = 6;
  for (int j = 0; j <= kQuads; ++j) {
    for (int i = 0; i <= kQuads; ++i) {
      floor.positions.push_back(centre + (3.1f * static_cast<float>(i - kQuads / 2)) * u +
                                (3.1f * static_cast<float>(j - kQuads / 2)) * v);
    }
  }
  for (std::uint32_t j = 0; j < kQuads; ++j) {
    for (std::uint32_t i = 0; i < kQuads; ++i) {
      const std::uint32_t a = j * (kQuads + 1) + i;
      floor.triangles.push_back({a, a + 1, a + kQuads + 2});
      floor.triangles.push_back({a, a + kQuads + 2, a + kQuads + 1});
    }
  }
  rt::Scene scene;
  ASSERT_TRUE(scene.add_static_mesh(floor).ok());
  JobSystem jobs(1);
  ASSERT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
  rt::CameraDesc desc;
  desc.eye = centre + 14.0f * up - 9.0f * v;
  desc.target = centre;
  desc.up = up;
  auto camera = rt::PinholeCamera::create(desc, 96, 96);
  ASSERT_TRUE(camera.ok());
  for (const Vec3& light : {centre + 20.0f * up + 3.0f * u, centre + 0.4f * up + 1.0f * v,
                            centre + 5e4f * up - 2e4f * u, centre + 3.0f * up + 4e3f * v}) {
    for (const int packet_rays : {1, 8, 64, 256, 512}) {
      for (const TriangleTest test : kTests) {
        const rt::RenderStats stats = render_lit(scene, *camera, light, packet_rays, test, jobs);
        EXPECT_GT(stats.shadow_rays, 2000u);
        EXPECT_EQ(stats.shadowed, 0u) << packet_rays << " rays per packet, light " << light.x << ","
                                      << light.y << "," << light.z;
      }
    }
  }
}

}  // namespace
}  // namespace sinew
