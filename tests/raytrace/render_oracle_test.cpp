// The ray tracer against brute force (docs/DESIGN.md section 4): for real models
// posed inside their sampled pose space, every ray's nearest hit (triangle,
// instance, t within 1e-5 relative) and every shadow ray's occlusion agree
// with intersecting every skinned triangle one by one; poses outside the
// pose space are detected and, through the fallback, still exact; and the
// numerical extremes of docs/DESIGN.md section 5 hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/gltf_importer.h"
#include "editor/mesh/subdivide.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "raytrace/traverse/traversal.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/brute_force.h"
#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#endif

namespace sinew {
namespace {

using rt::TriangleTest;
using testing_support::SoupTriangle;

constexpr TriangleTest kTests[] = {TriangleTest::kFast, TriangleTest::kWatertight};
const char* test_name(TriangleTest t) { return t == TriangleTest::kFast ? "fast" : "watertight"; }

// Deterministic uniform floats from the generator's raw bits (the standard
// distributions' output is implementation-defined).
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  float uniform() { return anim::unit_float(engine_()); }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  Vec3 in_box(const Aabb& b) {
    return {uniform(b.lower.x, b.upper.x), uniform(b.lower.y, b.upper.y), uniform(b.lower.z, b.upper.z)};
  }
  Vec3 direction() {
    const float z = uniform(-1.0f, 1.0f);
    const float phi = uniform(0.0f, 6.2831853f);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
  std::size_t index(std::size_t n) { return static_cast<std::size_t>(engine_() % n); }

 private:
  std::mt19937_64 engine_;
};

struct Subject {
  std::string name;
  int up_axis = 1;  // the model's up axis, for the ground plane
};

// gtest prints parameters in test names and failures: show the model's name.
void PrintTo(const Subject& subject, std::ostream* os) { *os << subject.name; }

Expected<character::Model> load(const Subject& subject) {
  const std::string shared = SINEW_SHARED_DIR;
  if (subject.name == "mannequin") return content::make_mannequin();
  if (subject.name == "cally") {
#if SINEW_HAVE_CAL3D
    return editor::import_cal3d(shared + "/content/cal3d/cally/cally.cfg");
#else
    return make_error(ErrorCode::kNotFound, "cally.cfg", "", "", "built without Cal3D");
#endif
  }
  return editor::import_gltf(shared + "/content/gltf/" + subject.name + "/" + subject.name + ".glb");
}

Aabb bounds_of(std::span<const Vec3> points) {
  Aabb box;
  for (const Vec3& p : points) box.extend(p);
  return box;
}

// A ground quad under `box` on the model's up axis, reaching well beyond it.
rt::StaticMeshDesc ground_under(const Aabb& box, int up) {
  const int a = (up + 1) % 3;
  const int b = (up + 2) % 3;
  const float reach = 3.0f * glm::length(box.extent());
  const Vec3 c = box.center();
  rt::StaticMeshDesc ground;
  for (int i = 0; i < 4; ++i) {
    Vec3 p(0.0f);
    p[up] = box.lower[up];
    p[a] = c[a] + ((i & 1) ? reach : -reach);
    p[b] = c[b] + ((i & 2) ? reach : -reach);
    ground.positions.push_back(p);
  }
  ground.triangles = {{0, 1, 3}, {0, 3, 2}};
  ground.material_colors = {Vec3(0.5f)};
  return ground;
}

// One model baked once in memory with the default pose space (every clip,
// every key and every 1/30 s), and the samples that bake saw.
struct Baked {
  character::Model model;
  character::InMemoryBake bake;
  std::vector<Affine3> samples;
  std::size_t bones = 0;
  std::size_t sample_count() const { return samples.size() / bones; }
  std::span<const Affine3> sample(std::size_t s) const { return std::span(samples).subspan(s * bones, bones); }
};

Baked bake(const Subject& subject, JobSystem& jobs, const character::BakeRequest& request = {}) {
  Baked out;
  auto model = load(subject);
  EXPECT_TRUE(model.ok()) << model.status().message();
  if (!model.ok()) return out;
  out.model = std::move(model).value();
  out.bones = out.model.skeleton.joint_count();
  auto samples = character::pose_space_skinning(out.model, request.pose_space, request.limits);
  EXPECT_TRUE(samples.ok()) << samples.status().message();
  out.samples = std::move(samples).value();
  auto baked = character::bake_in_memory(out.model, request, jobs);
  EXPECT_TRUE(baked.ok()) << baked.status().message();
  if (baked.ok()) out.bake = std::move(baked).value();
  return out;
}

// Cameras looking at `box` from outside (front, above-side, below-side) and
// one from its centre, so primary rays also start inside the character.
std::vector<rt::CameraDesc> cameras_around(const Aabb& box, int up) {
  const Vec3 c = box.center();
  const float r = 0.5f * glm::length(box.extent());
  Vec3 up_dir(0.0f), a(0.0f), b(0.0f);
  up_dir[up] = 1.0f;
  a[(up + 1) % 3] = 1.0f;
  b[(up + 2) % 3] = 1.0f;
  return {
      {c + 2.5f * r * a, c, up_dir, 50.0f},
      {c + 2.0f * r * (b + 0.8f * up_dir), c, up_dir, 45.0f},
      {c + 2.2f * r * (-a - b - 0.5f * up_dir), c, up_dir, 60.0f},
      {c + 0.01f * r * a, c + r * b, up_dir, 100.0f},
  };
}

struct Mismatch {
  std::size_t checked = 0;
  std::size_t wrong = 0;
  std::string first;
};

// Every pixel's single-ray hit and the renderer's (culled packets of
// `packet_rays` rays, render/stages/tile_stages.h) against brute force.
void compare_primary(const rt::Scene& scene, std::span<const SoupTriangle> soup, const rt::CameraDesc& desc,
                     int size, TriangleTest test, JobSystem& jobs, Mismatch& m, int packet_rays) {
  auto camera = rt::PinholeCamera::create(desc, size, size);
  ASSERT_TRUE(camera.ok()) << camera.status().message();
  const testing_support::ScreenBinner binner(soup, *camera);
  const std::size_t pixels = static_cast<std::size_t>(size) * static_cast<std::size_t>(size);
  std::vector<float> depth(pixels);
  std::vector<std::uint32_t> triangle(pixels), instance(pixels);
  rt::FrameBuffers buffers;
  buffers.width = buffers.height = size;
  buffers.depth = depth;
  buffers.triangle_id = triangle;
  buffers.instance_id = instance;
  rt::RenderSettings settings;
  settings.triangle_test = test;
  settings.packet_rays = packet_rays;
  rt::Renderer renderer;
  ASSERT_TRUE(renderer.render(scene, *camera, settings, buffers, jobs).ok());
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const Ray ray = camera->ray(x, y);
      const Hit ours = rt::intersect(scene, ray, test);
      const Hit ref = binner.nearest(soup, ray, x, y, test);
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x);
      const Hit packet{depth[i] / glm::length(ray.direction), 0.0f, 0.0f, triangle[i], instance[i]};
      m.checked += 2;
      if (!testing_support::same_nearest(packet, ref, soup, ray, test) && m.wrong++ == 0) {
        m.first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") " + test_name(test) + ", " +
                  std::to_string(packet_rays) + "-ray packets: t=" + std::to_string(packet.t) + " tri=" + std::to_string(packet.triangle_id) +
                  " ref t=" + std::to_string(ref.t) + " tri=" + std::to_string(ref.triangle_id);
      }
      if (!testing_support::same_nearest(ours, ref, soup, ray, test)) {
        if (m.wrong++ == 0) {
          m.first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") " + test_name(test) +
                    ": ours t=" + std::to_string(ours.t) + " tri=" + std::to_string(ours.triangle_id) +
                    " ref t=" + std::to_string(ref.t) + " tri=" + std::to_string(ref.triangle_id);
        }
      }
    }
  }
}

// Random rays: origins inside and around the world bounds, half aimed at a
// random point of a random triangle so that most of them hit something;
// every fourth is a segment (finite t_max) and also checked as a shadow ray.
void compare_random(const rt::Scene& scene, std::span<const SoupTriangle> soup, const Aabb& around,
                    std::size_t count, Random& random, Mismatch& m) {
  const Aabb region{around.center() - 0.75f * around.extent(), around.center() + 0.75f * around.extent()};
  for (std::size_t i = 0; i < count; ++i) {
    Ray ray;
    ray.origin = random.in_box(region);
    if (i % 2 == 0) {
      const SoupTriangle& tri = soup[random.index(soup.size())];
      const float u = random.uniform();
      const float v = random.uniform() * (1.0f - u);
      const Vec3 target = (1.0f - u - v) * tri.p0 + u * tri.p1 + v * tri.p2;
      ray.direction = target - ray.origin;
      if (ray.direction == Vec3(0.0f)) ray.direction = random.direction();
    } else {
      ray.direction = random.direction();
    }
    if (i % 4 == 1) ray.t_max = random.uniform(0.1f, 1.5f);
    for (const TriangleTest test : kTests) {
      const Hit ours = rt::intersect(scene, ray, test);
      const Hit ref = testing_support::nearest(soup, ray, test);
      ++m.checked;
      bool ok = testing_support::same_nearest(ours, ref, soup, ray, test);
      if (i % 4 == 1) ok = ok && rt::occluded(scene, ray, test) == testing_support::any_hit(soup, ray, test);
      if (!ok && m.wrong++ == 0) {
        m.first = std::string("random ray ") + std::to_string(i) + " " + test_name(test) +
                  ": ours t=" + std::to_string(ours.t) + " tri=" + std::to_string(ours.triangle_id) +
                  " ref t=" + std::to_string(ref.t) + " tri=" + std::to_string(ref.triangle_id);
      }
    }
  }
}

class RenderOracle : public ::testing::TestWithParam<Subject> {};

TEST_P(RenderOracle, PosesInsideThePoseSpaceMatchBruteForce) {
  JobSystem jobs(2);
  const Subject subject = GetParam();
  const Baked baked = bake(subject, jobs);
  ASSERT_GT(baked.bones, 0u);
  ASSERT_GT(baked.sample_count(), 0u);

  const rt::FuzzyCharacterView fuzzy = baked.bake.fuzzy.view();
  const Aabb rest = bounds_of(baked.model.mesh.positions);
  rt::Scene scene;
  auto character = scene.add_character(baked.model.mesh, fuzzy);
  ASSERT_TRUE(character.ok()) << character.status().message();
  ASSERT_TRUE(scene.add_instance(*character).ok());
  ASSERT_TRUE(scene.add_static_mesh(ground_under(rest, subject.up_axis)).ok());

  constexpr std::size_t kPoses = 50;
  const std::size_t poses = std::min(kPoses, baked.sample_count());
  Random random(0x5eed + poses);
  Mismatch primary, rays;
  std::size_t escapes = 0;
  for (std::size_t k = 0; k < poses; ++k) {
    const std::size_t s = k * baked.sample_count() / poses;
    ASSERT_TRUE(scene.set_bones(0, baked.sample(s)).ok());
    auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
    ASSERT_TRUE(stats.ok()) << stats.status().message();
    escapes += stats->escaped_checks;  // conservativeness: none for a sampled pose

    const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
    const Aabb posed = bounds_of(scene.instances()[0].positions);
    const auto cameras = cameras_around(posed, subject.up_axis);
    // Every pose gets a small image from one camera in turn; every tenth
    // pose (every 25th for meshes over 20k triangles, where the reference
    // costs most) a 256^2 image from all of them.
    const bool big = soup.size() > 20'000;
    const bool full = k % (big ? 25 : 10) == 0;
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      if (!full && c != k % cameras.size()) continue;
      const int size = full ? 256 : (big ? 32 : 48);
      // Packets of 8, 64, 256 and 512 rays in turn.
      const int packet_rays = std::array<int, 4>{8, 64, 256, 512}[(k + c) % 4];
      for (const TriangleTest test : kTests) {
        compare_primary(scene, soup, cameras[c], size, test, jobs, primary, packet_rays);
      }
    }
    // 2000 random rays per pose (10^5 over 50 poses), fewer for big meshes
    // so that brute force stays near 10^9 triangle tests per model.
    const std::size_t random_rays = std::clamp<std::size_t>(500'000'000 / (soup.size() * poses), 100, 2000);
    compare_random(scene, soup, posed, random_rays, random, rays);
  }
  EXPECT_EQ(escapes, 0u) << "a sampled pose left its fuzzy boxes";
  EXPECT_EQ(primary.wrong, 0u) << primary.checked << " primary rays; first: " << primary.first;
  EXPECT_EQ(rays.wrong, 0u) << rays.checked << " random rays; first: " << rays.first;
  RecordProperty("poses", static_cast<int>(poses));
  RecordProperty("primary_rays", static_cast<int>(primary.checked));
  RecordProperty("random_rays", static_cast<int>(rays.checked));
}

// Pose-space clusters (FuzzyBakeOptions::pose_clusters): sampled poses run
// on the cluster trees without a miss, poses halfway between two samples
// may leave a cluster (the bone goes back to its full tree), and poses
// mixing two far-apart samples bone by bone leave the pose space (the
// escape fallback); every one traces as brute force.
void expect_cluster_trees_match_brute_force(const Subject& subject, rt::BoneTreeKind trees) {
  JobSystem jobs(2);
  character::BakeRequest request;
  request.fuzzy.pose_clusters = 8;
  request.fuzzy.bone_trees = trees;
  const Baked baked = bake(subject, jobs, request);
  ASSERT_EQ(baked.bake.fuzzy.tree_kind, trees);
  ASSERT_GT(baked.bones, 0u);
  ASSERT_GT(baked.sample_count(), 1u);
  ASSERT_FALSE(baked.bake.fuzzy.clusters.empty());

  const Aabb rest = bounds_of(baked.model.mesh.positions);
  rt::Scene scene;
  auto character = scene.add_character(baked.model.mesh, baked.bake.fuzzy.view());
  ASSERT_TRUE(character.ok()) << character.status().message();
  ASSERT_TRUE(scene.add_instance(*character).ok());
  ASSERT_TRUE(scene.add_static_mesh(ground_under(rest, subject.up_axis)).ok());

  constexpr std::size_t kPoses = 12;
  Random random(0xc1u + baked.sample_count());
  Mismatch primary, rays;
  std::size_t sampled_misses = 0, sampled_escapes = 0, cluster_bones = 0;
  std::vector<Affine3> pose(baked.bones);
  for (std::size_t k = 0; k < kPoses; ++k) {
    const std::size_t s = k * baked.sample_count() / kPoses;
    const std::size_t far = (s + baked.sample_count() / 2) % baked.sample_count();
    const std::span<const Affine3> a = baked.sample(s), b = baked.sample(far);
    const int kind = static_cast<int>(k % 3);  // 0 sampled, 1 halfway, 2 mixed
    for (std::size_t bone = 0; bone < baked.bones; ++bone) {
      if (kind == 0) pose[bone] = a[bone];
      if (kind == 2) pose[bone] = bone % 2 == 0 ? a[bone] : b[bone];
      if (kind == 1) {
        const std::span<const Affine3> next = baked.sample((s + 1) % baked.sample_count());
        for (std::size_t r = 0; r < 3; ++r) pose[bone].rows[r] = 0.5f * (a[bone].rows[r] + next[bone].rows[r]);
      }
    }
    ASSERT_TRUE(scene.set_bones(0, pose).ok());
    auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
    ASSERT_TRUE(stats.ok()) << stats.status().message();
    if (kind == 0) {
      sampled_misses += stats->cluster_misses;
      sampled_escapes += stats->escaped_checks;
      cluster_bones += stats->cluster_bones;
    }
    const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
    const Aabb posed = bounds_of(scene.instances()[0].positions);
    const auto cameras = cameras_around(posed, subject.up_axis);
    const bool big = soup.size() > 20'000;
    const int packet_rays = std::array<int, 4>{8, 64, 256, 512}[k % 4];
    for (const TriangleTest test : kTests) {
      compare_primary(scene, soup, cameras[k % cameras.size()], big ? 32 : 64, test, jobs, primary, packet_rays);
    }
    compare_random(scene, soup, posed, std::clamp<std::size_t>(100'000'000 / (soup.size() * kPoses), 100, 1000),
                   random, rays);
  }
  EXPECT_EQ(sampled_misses, 0u) << "a sampled pose left the cluster its bone picked";
  EXPECT_EQ(sampled_escapes, 0u) << "a sampled pose left its fuzzy boxes";
  EXPECT_GT(cluster_bones, 0u) << "no bone used a cluster's tree";
  EXPECT_EQ(primary.wrong, 0u) << primary.checked << " primary rays; first: " << primary.first;
  EXPECT_EQ(rays.wrong, 0u) << rays.checked << " random rays; first: " << rays.first;
}

TEST_P(RenderOracle, PoseClusterTreesMatchBruteForce) {
  expect_cluster_trees_match_brute_force(GetParam(), rt::BoneTreeKind::kKdTree);
}

// The same with BVH bone trees (docs/RAYTRACE.md "Bone trees: kd-tree or
// BVH"): each bone's and each cluster's tree a BVH over the same boxes.
TEST_P(RenderOracle, BvhBoneTreesMatchBruteForce) {
  expect_cluster_trees_match_brute_force(GetParam(), rt::BoneTreeKind::kBvh);
}

// The paper's larger Cally variants (sinew-editor subdivide): every level
// traces like brute force. A smaller budget than the suite above (one clip's
// poses, small images, few random rays), as the reference costs grow with
// the 855k triangles of level 4.
TEST(SubdividedCallyOracle, LevelsOneToFourMatchBruteForce) {
#if SINEW_HAVE_CAL3D
  const std::string cfg = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";
  auto cally = editor::import_cal3d(cfg);
  if (!cally.ok()) GTEST_SKIP() << cally.status().message();
  JobSystem jobs(2);
  for (int level = 1; level <= 4; ++level) {
    SCOPED_TRACE("level " + std::to_string(level));
    auto model = editor::subdivide(*cally, level);
    ASSERT_TRUE(model.ok()) << model.status().message();
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kClip;
    request.pose_space.clips = {"walk"};
    request.pose_space.samples = 6;
    request.pose_space.every_frame_30hz = false;
    auto samples = character::pose_space_skinning(*model, request.pose_space, {});
    ASSERT_TRUE(samples.ok()) << samples.status().message();
    auto baked = character::bake_in_memory(*model, request, jobs);
    ASSERT_TRUE(baked.ok()) << baked.status().message();
    const std::size_t bones = model->skeleton.joint_count();
    const std::size_t sample_count = samples->size() / bones;
    ASSERT_GT(sample_count, 2u);

    rt::Scene scene;
    auto character = scene.add_character(model->mesh, baked->fuzzy.view());
    ASSERT_TRUE(character.ok()) << character.status().message();
    ASSERT_TRUE(scene.add_instance(*character).ok());
    const Aabb rest = bounds_of(model->mesh.positions);
    ASSERT_TRUE(scene.add_static_mesh(ground_under(rest, 2)).ok());
    Random random(0xc0ffee + static_cast<std::uint64_t>(level));
    Mismatch primary, rays;
    std::size_t escapes = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t s = k * sample_count / 3;
      ASSERT_TRUE(scene.set_bones(0, std::span(*samples).subspan(s * bones, bones)).ok());
      auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
      ASSERT_TRUE(stats.ok()) << stats.status().message();
      escapes += stats->escaped_checks;
      const std::vector<SoupTriangle> soup = testing_support::world_triangles(scene);
      const Aabb posed = bounds_of(scene.instances()[0].positions);
      const auto cameras = cameras_around(posed, 2);
      for (const TriangleTest test : kTests) {
        compare_primary(scene, soup, cameras[k % cameras.size()], 48, test, jobs, primary,
                        std::array<int, 4>{8, 64, 256, 512}[k % 4]);
      }
      compare_random(scene, soup, posed, 100, random, rays);
    }
    EXPECT_EQ(escapes, 0u) << "a sampled pose left its fuzzy boxes";
    EXPECT_EQ(primary.wrong, 0u) << primary.checked << " primary rays; first: " << primary.first;
    EXPECT_EQ(rays.wrong, 0u) << rays.checked << " random rays; first: " << rays.first;
    EXPECT_EQ(model->mesh.triangle_count(), cally->mesh.triangle_count() << (2 * level));
  }
#else
  GTEST_SKIP() << "built without Cal3D";
#endif
}

std::vector<Subject> subjects() {
  std::vector<Subject> out{{"mannequin", 1}};
#if SINEW_HAVE_CAL3D
  out.push_back({"cally", 2});
#endif
  out.push_back({"CesiumMan", 2});
  out.push_back({"BrainStem", 2});
  return out;
}

std::string subject_name(const ::testing::TestParamInfo<Subject>& param) { return param.param.name; }

INSTANTIATE_TEST_SUITE_P(Models, RenderOracle, ::testing::ValuesIn(subjects()), subject_name);

}  // namespace
}  // namespace sinew
