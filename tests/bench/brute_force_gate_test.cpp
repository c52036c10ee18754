// The benchmarks' brute-force gate (brute_force_gate.h) on hand-built hits:
// one pixel whose ray crosses a plane at (0, 0, 0), beside the vertical
// edge x = -d that two triangles of the plane share. The reference (the
// watertight test over every triangle) hits the large triangle on the +x
// side; a contender may report the small triangle on the -x side at the same
// depth.
#include <gtest/gtest.h>

#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/scene/scene.h"
#include "tests/bench/brute_force_gate.h"

namespace sinew::bench {
namespace {

struct EdgeScene {
  rt::Scene scene;
  std::uint32_t instance = 0;
  rt::PinholeCamera camera;
};

// Triangle 0 (large, +x side): height 10 over the shared edge, so the
// crossing point's distance d is d / 10 in its barycentrics. Triangle 1
// (small, -x side): height 1, so the point lies d / 1 outside it.
EdgeScene edge_scene(float d) {
  rt::StaticMeshDesc mesh;
  mesh.positions = {{-d, -10.0f, 0.0f}, {-d, 10.0f, 0.0f}, {-d + 10.0f, 0.0f, 0.0f}, {-d - 1.0f, 0.0f, 0.0f}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}};
  rt::Scene scene;
  const auto id = scene.add_static_mesh(mesh);
  EXPECT_TRUE(id.ok());
  rt::CameraDesc desc;
  desc.eye = {0.0f, 0.0f, 5.0f};
  desc.target = {0.0f, 0.0f, 0.0f};
  desc.up = {0.0f, 1.0f, 0.0f};
  auto camera = rt::PinholeCamera::create(desc, 1, 1);
  EXPECT_TRUE(camera.ok());
  return {std::move(scene), id.ok() ? *id : 0, *camera};
}

Hit hit_on(std::uint32_t triangle, std::uint32_t instance) {
  Hit h;
  h.t = 5.0f;
  h.triangle_id = triangle;
  h.instance_id = instance;
  return h;
}

TEST(BruteForceGate, TheTriangleAcrossAnEdgeTheReferenceHitsIsAGraze) {
  // d = 5e-5: the reference's hit lies 5e-6 inside its edge (a graze), the
  // other triangle's 5e-5 outside it (beyond the 1e-5 a lone hit may be).
  EdgeScene s = edge_scene(5e-5f);
  const BruteForceGate gate(s.scene, s.camera, 1);
  const std::vector<Hit> same{hit_on(0, s.instance)};
  const GateResult exact = gate.check(same);
  EXPECT_EQ(exact.checked, 1u);
  EXPECT_EQ(exact.mismatched, 0u);
  EXPECT_EQ(exact.grazes, 0u);
  const std::vector<Hit> across{hit_on(1, s.instance)};
  const GateResult tie = gate.check(across);
  EXPECT_EQ(tie.mismatched, 0u);
  EXPECT_EQ(tie.grazes, 1u);
}

TEST(BruteForceGate, TheTriangleAcrossAnEdgeFarFromTheHitDiffers) {
  // d = 5e-4: the reference's hit lies 5e-5 inside its edge, no graze.
  EdgeScene s = edge_scene(5e-4f);
  const BruteForceGate gate(s.scene, s.camera, 1);
  const std::vector<Hit> across{hit_on(1, s.instance)};
  EXPECT_EQ(gate.check(across).mismatched, 1u);
  const std::vector<Hit> missed{Hit{}};
  EXPECT_EQ(gate.check(missed).mismatched, 1u);
}

}  // namespace
}  // namespace sinew::bench
