// Midpoint subdivision (editor/mesh/subdivide.h): the documented order on
// hand-built meshes, no cracks and closed meshes staying closed, the skin
// weight merge against hand-computed rows, counts against an independent
// std::set edge count, the bind-pose surface against double-precision
// barycentric points of the parent triangle, errors, and a bake of the
// result.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "editor/mesh/subdivide.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/same_model.h"

#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#endif

namespace sinew::editor {
namespace {

using Triangle = std::array<std::uint32_t, 3>;
using JointRow = std::array<std::uint16_t, kMaxInfluences>;
using WeightRow = std::array<float, kMaxInfluences>;

// A model whose every vertex is bound to joint 0 alone, one material.
character::Model make_model(std::vector<Vec3> positions, std::vector<Triangle> triangles) {
  character::Model model;
  model.source = "test";
  const std::size_t vertices = positions.size();
  model.mesh.positions = std::move(positions);
  JointRow joints{};
  WeightRow weights{};
  weights[0] = 1.0f;
  model.mesh.joints.assign(vertices, joints);
  model.mesh.weights.assign(vertices, weights);
  model.mesh.triangle_material.assign(triangles.size(), 0);
  model.mesh.triangles = std::move(triangles);
  model.mesh.material_colors = {Vec3(1.0f, 1.0f, 1.0f)};
  model.material_names = {"white"};
  return model;
}

character::Model tetrahedron() {
  // Outward-facing, consistently wound.
  return make_model({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)},
                    {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

const character::Model& mannequin() {
  static const character::Model model = content::make_mannequin().value();
  return model;
}

character::Model subdivided(const character::Model& model, int levels) {
  auto result = subdivide(model, levels);
  EXPECT_TRUE(result.ok()) << result.status().message();
  return std::move(result).value();
}

std::pair<std::uint32_t, std::uint32_t> undirected(std::uint32_t a, std::uint32_t b) {
  return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
}

std::size_t unique_edge_count(const SkinnedMesh& mesh) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const Triangle& t : mesh.triangles) {
    edges.insert(undirected(t[0], t[1]));
    edges.insert(undirected(t[1], t[2]));
    edges.insert(undirected(t[2], t[0]));
  }
  return edges.size();
}

// How many triangles use each directed edge.
std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed_edge_uses(const SkinnedMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const Triangle& t : mesh.triangles) {
    ++uses[{t[0], t[1]}];
    ++uses[{t[1], t[2]}];
    ++uses[{t[2], t[0]}];
  }
  return uses;
}

// Closed and consistently oriented: every directed edge is used once and
// its reverse once, so every undirected edge has exactly two triangles.
void expect_closed_and_oriented(const SkinnedMesh& mesh, const std::string& what) {
  const auto uses = directed_edge_uses(mesh);
  int bad = 0;
  for (const auto& [edge, count] : uses) {
    const auto reverse = uses.find({edge.second, edge.first});
    if (count != 1 || reverse == uses.end() || reverse->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0) << what << ": directed edges not matched by exactly one reverse edge";
}

// ------------------------------------------------------------ documented order

TEST(Subdivide, SingleTriangleOneLevelFollowsTheDocumentedOrder) {
  character::Model model = make_model({Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 2, 6)}, {{0, 1, 2}});
  model.mesh.normals = {Vec3(0, 0, 1), Vec3(0, 1, 0), Vec3(1, 0, 0)};
  model.mesh.uvs = {Vec2(0.0f, 0.0f), Vec2(1.0f, 0.0f), Vec2(0.0f, 1.0f)};
  model.mesh.material_colors.push_back(Vec3(1.0f, 0.0f, 0.0f));
  model.mesh.triangle_material = {1};

  const character::Model out = subdivided(model, 1);
  const SkinnedMesh& mesh = out.mesh;
  ASSERT_EQ(mesh.vertex_count(), 6u);
  ASSERT_EQ(mesh.triangle_count(), 4u);
  ASSERT_EQ(mesh.normals.size(), 6u);
  ASSERT_EQ(mesh.uvs.size(), 6u);
  EXPECT_EQ(out.source, "test (subdivided 1)");

  // Originals keep their indices; midpoints of (v0,v1), (v1,v2), (v2,v0).
  EXPECT_EQ(mesh.positions[0], Vec3(0, 0, 0));
  EXPECT_EQ(mesh.positions[1], Vec3(4, 0, 0));
  EXPECT_EQ(mesh.positions[2], Vec3(0, 2, 6));
  EXPECT_EQ(mesh.positions[3], Vec3(2, 0, 0));
  EXPECT_EQ(mesh.positions[4], Vec3(2, 1, 3));
  EXPECT_EQ(mesh.positions[5], Vec3(0, 1, 3));
  EXPECT_EQ(mesh.uvs[3], Vec2(0.5f, 0.0f));
  EXPECT_EQ(mesh.uvs[4], Vec2(0.5f, 0.5f));
  EXPECT_EQ(mesh.uvs[5], Vec2(0.0f, 0.5f));
  const float r = 1.0f / std::sqrt(2.0f);
  for (const auto& [index, expected] :
       {std::make_pair(3, Vec3(0, r, r)), std::make_pair(4, Vec3(r, r, 0)), std::make_pair(5, Vec3(r, 0, r))}) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mesh.normals[index][c], expected[c], 1e-6f) << index;
  }

  // Corners at v0, v1, v2, then the middle, each with the parent's winding.
  const std::vector<Triangle> expected = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
  EXPECT_EQ(mesh.triangles, expected);
  EXPECT_EQ(mesh.triangle_material, std::vector<std::uint32_t>(4, 1));
  EXPECT_EQ(mesh.material_colors, model.mesh.material_colors);
  EXPECT_EQ(out.material_names, model.material_names);

  // Same winding: every child's geometric normal points along the parent's.
  const Vec3 parent_normal = glm::cross(mesh.positions[1] - mesh.positions[0], mesh.positions[2] - mesh.positions[0]);
  for (const Triangle& t : mesh.triangles) {
    const Vec3 n = glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]);
    EXPECT_GT(glm::dot(n, parent_normal), 0.0f);
  }
}

TEST(Subdivide, OppositeNormalsFallBackToTheFirstEndpoint) {
  character::Model model = make_model({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}});
  model.mesh.normals = {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(0, 0, 1)};
  const SkinnedMesh mesh = subdivided(model, 1).mesh;
  EXPECT_EQ(mesh.normals[3], Vec3(0, 0, 1));  // (v0, v1): v0 first
  EXPECT_EQ(mesh.normals[4], Vec3(0, 0, -1));  // (v1, v2): v1 first
  EXPECT_EQ(mesh.normals[5], Vec3(0, 0, 1));
  EXPECT_TRUE(mesh.uvs.empty());
}

// ------------------------------------------------------------ no cracks

TEST(Subdivide, SharedEdgeGetsOneMidpoint) {
  // Two triangles sharing edge 1-2, met as (1,2) in the first and (2,1) in the second.
  const character::Model model =
      make_model({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}, {{0, 1, 2}, {2, 1, 3}});
  const SkinnedMesh mesh = subdivided(model, 1).mesh;
  ASSERT_EQ(mesh.vertex_count(), 9u);  // 4 + 5 unique edges
  ASSERT_EQ(mesh.triangle_count(), 8u);
  // Edges in first-met order: (0,1)=4, (1,2)=5, (2,0)=6, then (1,3)=7, (3,2)=8.
  EXPECT_EQ(mesh.positions[5], Vec3(0.5f, 0.5f, 0.0f));
  EXPECT_EQ(mesh.positions[7], Vec3(1.0f, 0.5f, 0.0f));
  EXPECT_EQ(mesh.positions[8], Vec3(0.5f, 1.0f, 0.0f));
  const std::vector<Triangle> second = {mesh.triangles[4], mesh.triangles[5], mesh.triangles[6], mesh.triangles[7]};
  const std::vector<Triangle> expected_second = {{2, 5, 8}, {5, 1, 7}, {8, 7, 3}, {5, 7, 8}};
  EXPECT_EQ(second, expected_second);

  // Every edge is used by at most two triangles; the 4 halves of the shared
  // edge's interior plus the 6 inner edges by exactly two, the 8 boundary halves by one.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const Triangle& t : mesh.triangles) {
    ++uses[undirected(t[0], t[1])];
    ++uses[undirected(t[1], t[2])];
    ++uses[undirected(t[2], t[0])];
  }
  int once = 0;
  int twice = 0;
  for (const auto& [edge, count] : uses) {
    EXPECT_LE(count, 2);
    (count == 1 ? once : twice) += 1;
  }
  EXPECT_EQ(once, 8);   // the original 4 boundary edges, halved
  EXPECT_EQ(twice, 8);  // the shared edge's 2 halves + 3 inner edges per parent
}

TEST(Subdivide, ClosedMeshStaysClosed) {
  const character::Model tet = tetrahedron();
  expect_closed_and_oriented(tet.mesh, "tetrahedron");
  for (int levels = 1; levels <= 3; ++levels) {
    expect_closed_and_oriented(subdivided(tet, levels).mesh, "tetrahedron level " + std::to_string(levels));
  }
  expect_closed_and_oriented(mannequin().mesh, "mannequin");
  expect_closed_and_oriented(subdivided(mannequin(), 1).mesh, "mannequin level 1");
}

// ------------------------------------------------------------ skin weights

// Two triangles (a, b, c) and (b, a, c): the midpoint of a-b is vertex 3 in
// both, met from either end.
std::pair<JointRow, WeightRow> midpoint_influences(const JointRow& joints_a, const WeightRow& weights_a,
                                                   const JointRow& joints_b, const WeightRow& weights_b,
                                                   bool reversed) {
  character::Model model = make_model({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                                   {reversed ? Triangle{1, 0, 2} : Triangle{0, 1, 2}});
  model.mesh.joints[0] = joints_a;
  model.mesh.weights[0] = weights_a;
  model.mesh.joints[1] = joints_b;
  model.mesh.weights[1] = weights_b;
  const SkinnedMesh mesh = subdivided(model, 1).mesh;
  return {mesh.joints[3], mesh.weights[3]};
}

TEST(Subdivide, WeightsMergeTheUnionAtHalfWeight) {
  const JointRow joints_a = {1, 2};
  const WeightRow weights_a = {0.75f, 0.25f};
  const JointRow joints_b = {2, 3};
  const WeightRow weights_b = {0.5f, 0.5f};
  // j1: 0.375, j2: 0.125 + 0.25 = 0.375, j3: 0.25; ties broken by joint.
  const JointRow expected_joints = {1, 2, 3, 0, 0, 0, 0, 0};
  const WeightRow expected_weights = {0.375f, 0.375f, 0.25f, 0, 0, 0, 0, 0};
  for (const bool reversed : {false, true}) {
    const auto [joints, weights] = midpoint_influences(joints_a, weights_a, joints_b, weights_b, reversed);
    EXPECT_EQ(joints, expected_joints) << reversed;
    EXPECT_EQ(weights, expected_weights) << reversed;
  }
}

TEST(Subdivide, WeightsKeepTheHeaviestEightAndRenormalise) {
  const JointRow joints_a = {0, 1, 2, 3, 4, 5, 6, 7};
  const WeightRow weights_a = {0.30f, 0.20f, 0.15f, 0.10f, 0.10f, 0.05f, 0.05f, 0.05f};
  const JointRow joints_b = {17, 16, 15, 14, 13, 12, 11, 10};
  const WeightRow weights_b = {0.02f, 0.03f, 0.05f, 0.10f, 0.10f, 0.20f, 0.25f, 0.25f};
  // Halves: j0 .15, j10 .125, j11 .125, j1 .10, j12 .10, j2 .075, then a
  // four-way tie at .05 (j3, j4, j13, j14) of which the lower joints win.
  const JointRow expected_joints = {0, 10, 11, 1, 12, 2, 3, 4};
  const std::array<double, kMaxInfluences> halves = {0.15, 0.125, 0.125, 0.10, 0.10, 0.075, 0.05, 0.05};
  double kept = 0.0;
  for (const double h : halves) kept += h;
  const auto [joints, weights] = midpoint_influences(joints_a, weights_a, joints_b, weights_b, false);
  EXPECT_EQ(joints, expected_joints);
  double sum = 0.0;
  for (std::size_t i = 0; i < kMaxInfluences; ++i) {
    EXPECT_NEAR(static_cast<double>(weights[i]), halves[i] / kept, 1e-6) << i;
    sum += static_cast<double>(weights[i]);
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);

  // Met from the other end: bit-identical.
  const auto [joints_r, weights_r] = midpoint_influences(joints_a, weights_a, joints_b, weights_b, true);
  EXPECT_EQ(joints_r, joints);
  EXPECT_EQ(weights_r, weights);
}

TEST(Subdivide, EveryMidpointWeightRowIsSortedAndNormalised) {
  const SkinnedMesh mesh = subdivided(mannequin(), 2).mesh;
  const std::size_t joint_count = mannequin().skeleton.joint_count();
  // The originals keep their rows as imported (not necessarily sorted).
  for (std::size_t v = mannequin().mesh.vertex_count(); v < mesh.vertex_count(); ++v) {
    double sum = 0.0;
    for (std::size_t i = 0; i < kMaxInfluences; ++i) {
      const float w = mesh.weights[v][i];
      ASSERT_GE(w, 0.0f) << v;
      if (w == 0.0f) {
        ASSERT_EQ(mesh.joints[v][i], 0) << "unused slot of vertex " << v;
      } else {
        ASSERT_LT(mesh.joints[v][i], joint_count) << v;
        if (i > 0) {
          ASSERT_LE(w, mesh.weights[v][i - 1]) << v;
        }
      }
      sum += static_cast<double>(w);
    }
    ASSERT_NEAR(sum, 1.0, 1e-5) << v;
  }
}

// ------------------------------------------------------------ counts

struct Counts {
  std::size_t vertices;
  std::size_t triangles;
};

// Subdivides 1..4 levels and checks T * 4^L triangles and V + E vertices per
// level, E counted independently from the previous level's result.
std::vector<Counts> checked_counts(const character::Model& model, int max_levels) {
  std::vector<Counts> counts;
  character::Model previous = model;
  std::size_t expected_vertices = model.mesh.vertex_count();
  std::size_t expected_triangles = model.mesh.triangle_count();
  for (int levels = 1; levels <= max_levels; ++levels) {
    expected_vertices += unique_edge_count(previous.mesh);
    expected_triangles *= 4;
    character::Model current = subdivided(model, levels);
    EXPECT_EQ(current.mesh.triangle_count(), expected_triangles) << "level " << levels;
    EXPECT_EQ(current.mesh.vertex_count(), expected_vertices) << "level " << levels;
    EXPECT_EQ(current.mesh.joints.size(), expected_vertices);
    EXPECT_EQ(current.mesh.weights.size(), expected_vertices);
    EXPECT_EQ(current.mesh.normals.size(), model.mesh.normals.empty() ? 0 : expected_vertices);
    EXPECT_EQ(current.mesh.uvs.size(), model.mesh.uvs.empty() ? 0 : expected_vertices);
    EXPECT_EQ(current.mesh.triangle_material.size(), expected_triangles);
    counts.push_back({current.mesh.vertex_count(), current.mesh.triangle_count()});
    previous = std::move(current);
  }
  return counts;
}

void print_counts(const std::string& name, const character::Model& model, const std::vector<Counts>& counts) {
  std::cout << name << " level 0: " << model.mesh.vertex_count() << " vertices, " << model.mesh.triangle_count()
            << " triangles\n";
  for (std::size_t i = 0; i < counts.size(); ++i) {
    std::cout << name << " level " << i + 1 << ": " << counts[i].vertices << " vertices, " << counts[i].triangles
              << " triangles\n";
  }
}

TEST(Subdivide, MannequinCountsLevels1To4) {
  const auto counts = checked_counts(mannequin(), 4);
  // Closed: every edge has two triangles, so E = 3F/2 and every level adds
  // 3F/2 vertices, F the previous level's triangle count.
  ASSERT_EQ(counts.size(), 4u);
  std::size_t vertices = mannequin().mesh.vertex_count();
  std::size_t triangles = mannequin().mesh.triangle_count();
  for (const Counts& c : counts) {
    vertices += triangles * 3 / 2;
    triangles *= 4;
    EXPECT_EQ(c.vertices, vertices);
    EXPECT_EQ(c.triangles, triangles);
  }
  print_counts("mannequin", mannequin(), counts);
}

TEST(Subdivide, IteratingOneLevelEqualsSeveralLevels) {
  const character::Model twice = subdivided(subdivided(mannequin(), 1), 2);
  const character::Model at_once = subdivided(mannequin(), 3);
  EXPECT_EQ(twice.mesh.triangles, at_once.mesh.triangles);
  EXPECT_EQ(twice.mesh.positions, at_once.mesh.positions);
  EXPECT_EQ(twice.mesh.weights, at_once.mesh.weights);
  EXPECT_EQ(twice.mesh.joints, at_once.mesh.joints);
}

#if SINEW_HAVE_CAL3D
const std::string kCallyCfg = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";

TEST(Subdivide, CallyCountsLevels1To4) {
  if (!std::filesystem::exists(kCallyCfg)) GTEST_SKIP() << "Cally not found at " << kCallyCfg;
  auto cally = import_cal3d(kCallyCfg);
  ASSERT_TRUE(cally.ok()) << cally.status().message();
  const auto counts = checked_counts(*cally, 4);
  print_counts("cally", *cally, counts);
}
#endif

// ------------------------------------------------------------ same surface

// Barycentric coordinates (in the parent's corners) of child `k`'s corners,
// per the documented order.
std::array<std::array<double, 3>, 3> child_corners(int k) {
  const std::array<double, 3> v0 = {1, 0, 0}, v1 = {0, 1, 0}, v2 = {0, 0, 1};
  const std::array<double, 3> m01 = {0.5, 0.5, 0}, m12 = {0, 0.5, 0.5}, m20 = {0.5, 0, 0.5};
  switch (k) {
    case 0: return {v0, m01, m20};
    case 1: return {m01, v1, m12};
    case 2: return {m20, m12, v2};
    default: return {m01, m12, m20};
  }
}

// Composes the child path of a level-L triangle into barycentrics of its
// level-0 ancestor: digit i (base 4, most significant first) picks a child.
std::array<std::array<double, 3>, 3> descendant_corners(std::size_t triangle, int levels) {
  std::array<std::array<double, 3>, 3> corners = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int level = levels - 1; level >= 0; --level) {
    const int k = static_cast<int>((triangle >> (2 * level)) & 3u);
    const auto child = child_corners(k);
    std::array<std::array<double, 3>, 3> next{};
    for (int c = 0; c < 3; ++c) {
      for (int j = 0; j < 3; ++j) {
        for (int p = 0; p < 3; ++p) next[c][p] += child[c][j] * corners[j][p];
      }
    }
    corners = next;
  }
  return corners;
}

TEST(Subdivide, LevelOneCornersAreExactParentMidpoints) {
  const SkinnedMesh& parent = mannequin().mesh;
  const SkinnedMesh child = subdivided(mannequin(), 1).mesh;
  for (std::size_t t = 0; t < parent.triangle_count(); ++t) {
    const Vec3 a = parent.positions[parent.triangles[t][0]];
    const Vec3 b = parent.positions[parent.triangles[t][1]];
    const Vec3 c = parent.positions[parent.triangles[t][2]];
    const Vec3 ab = (a + b) * 0.5f, bc = (b + c) * 0.5f, ca = (c + a) * 0.5f;
    const std::array<std::array<Vec3, 3>, 4> expected = {{{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}}};
    for (std::size_t k = 0; k < 4; ++k) {
      for (std::size_t corner = 0; corner < 3; ++corner) {
        ASSERT_EQ(child.positions[child.triangles[4 * t + k][corner]], expected[k][corner])
            << "triangle " << t << " child " << k << " corner " << corner;
      }
    }
  }
}

TEST(Subdivide, LevelThreeCornersLieOnTheParentAtTheirBarycentrics) {
  constexpr int kLevels = 3;
  const SkinnedMesh& parent = mannequin().mesh;
  const SkinnedMesh child = subdivided(mannequin(), kLevels).mesh;
  const std::size_t per_parent = std::size_t{1} << (2 * kLevels);
  double worst = 0.0;
  for (std::size_t t = 0; t < child.triangle_count(); ++t) {
    const Triangle& ancestor = parent.triangles[t / per_parent];
    const auto bary = descendant_corners(t % per_parent, kLevels);
    for (std::size_t corner = 0; corner < 3; ++corner) {
      const Vec3 actual = child.positions[child.triangles[t][corner]];
      for (int axis = 0; axis < 3; ++axis) {
        double expected = 0.0;
        for (std::size_t p = 0; p < 3; ++p) {
          expected += bary[corner][p] * static_cast<double>(parent.positions[ancestor[p]][axis]);
        }
        worst = std::max(worst, std::abs(static_cast<double>(actual[axis]) - expected));
      }
    }
  }
  // The mannequin is 1.8 m tall; float averages round to ~1e-7 m per level.
  EXPECT_LT(worst, 1e-6);
}

// ------------------------------------------------------------ errors

TEST(Subdivide, LevelsOutsideTheRangeAreInvalidArguments) {
  for (const int levels : {-1, kMaxSubdivisionLevels + 1}) {
    auto result = subdivide(tetrahedron(), levels);
    ASSERT_FALSE(result.ok()) << levels;
    EXPECT_EQ(result.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(result.status().field(), "levels");
    EXPECT_EQ(result.status().value(), std::to_string(levels));
  }
}

TEST(Subdivide, OutOfRangeVertexIndexNamesTheTriangle) {
  character::Model model = tetrahedron();
  model.mesh.triangles[2][1] = 4;
  for (const int levels : {0, 1}) {
    auto result = subdivide(model, levels);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.status().code(), ErrorCode::kInvalidData);
    EXPECT_EQ(result.status().file(), "test");
    EXPECT_EQ(result.status().field(), "triangles[2]");
    EXPECT_EQ(result.status().value(), "4");
  }
}

TEST(Subdivide, MismatchedAttributeArraysAreInvalidData) {
  character::Model model = tetrahedron();
  model.mesh.normals = {Vec3(0, 0, 1)};
  auto result = subdivide(model, 1);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kInvalidData);
  EXPECT_EQ(result.status().field(), "mesh.normals");

  model = tetrahedron();
  model.mesh.weights.pop_back();
  result = subdivide(model, 1);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().field(), "mesh.weights");
}

TEST(Subdivide, TooManyTrianglesIsLimitExceeded) {
  // 32,769 * 4^8 > 2^31 triangles: refused before anything is built.
  std::vector<Triangle> triangles(32769, Triangle{0, 1, 2});
  const character::Model model = make_model({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, triangles);
  auto result = subdivide(model, kMaxSubdivisionLevels);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_EQ(result.status().field(), "levels");
}

TEST(Subdivide, LevelZeroIsAnIdenticalCopy) {
  const character::Model& model = mannequin();
  const character::Model copy = subdivided(model, 0);
  EXPECT_EQ(copy.source, model.source);
  testing_support::expect_same_model(model, copy);
}

TEST(Subdivide, EmptyMeshStaysEmpty) {
  const character::Model model = make_model({}, {});
  const character::Model out = subdivided(model, 3);
  EXPECT_EQ(out.mesh.vertex_count(), 0u);
  EXPECT_EQ(out.mesh.triangle_count(), 0u);
}

// ------------------------------------------------------------ bake oracle

TEST(Subdivide, SubdividedMannequinBakes) {
  const character::Model model = subdivided(mannequin(), 1);
  JobSystem jobs(2);
  auto bake = character::bake_in_memory(model, character::BakeRequest{}, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  EXPECT_EQ(bake->fuzzy.triangle_bone.size(), model.mesh.triangle_count());
  EXPECT_EQ(bake->fuzzy.bone_count, model.skeleton.joint_count());
}

}  // namespace
}  // namespace sinew::editor
