#include "editor/mesh/subdivide.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sinew::editor {

namespace {

// Indices are uint32 in SkinnedMesh; 2^31 leaves headroom for code that
// stores them in signed ints.
constexpr std::uint64_t kMaxElements = std::uint64_t{1} << 31;

using JointRow = std::array<std::uint16_t, kMaxInfluences>;
using WeightRow = std::array<float, kMaxInfluences>;

// The counts a mesh will have after some levels. Edge counts follow
// E' <= 2E + 3T: every new edge is a half of an old edge or one of a
// triangle's three inner edges. Equality holds unless a triangle repeats a
// corner or two triangles share two edges (a double-sided sheet), so the
// limit check can only err on the safe side, and the bound sizes the edge
// tables.
struct MeshCounts {
  std::uint64_t vertices = 0;
  std::uint64_t edges = 0;
  std::uint64_t triangles = 0;
};

MeshCounts counts_after(MeshCounts counts, int levels) {
  for (int level = 0; level < levels; ++level) {
    counts = {counts.vertices + counts.edges, 2 * counts.edges + 3 * counts.triangles,
              4 * counts.triangles};
  }
  return counts;
}

Status size_error(const character::Model& model, const char* field, std::size_t size,
                  const std::string& expected) {
  return make_error(ErrorCode::kInvalidData, model.source, field, std::to_string(size),
                    "expected " + expected);
}

// The per-vertex and per-triangle arrays must line up, or the averages
// below would read past their ends.
Status check_array_sizes(const character::Model& model) {
  const SkinnedMesh& mesh = model.mesh;
  const std::size_t vertices = mesh.vertex_count();
  const std::string per_vertex = std::to_string(vertices) + " entries, one per vertex";
  const std::string optional_per_vertex = "0 or " + per_vertex;
  if (mesh.joints.size() != vertices) {
    return size_error(model, "mesh.joints", mesh.joints.size(), per_vertex);
  }
  if (mesh.weights.size() != vertices) {
    return size_error(model, "mesh.weights", mesh.weights.size(), per_vertex);
  }
  if (!mesh.normals.empty() && mesh.normals.size() != vertices) {
    return size_error(model, "mesh.normals", mesh.normals.size(), optional_per_vertex);
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != vertices) {
    return size_error(model, "mesh.uvs", mesh.uvs.size(), optional_per_vertex);
  }
  const std::size_t triangles = mesh.triangle_count();
  if (!mesh.triangle_material.empty() && mesh.triangle_material.size() != triangles) {
    return size_error(model, "mesh.triangle_material", mesh.triangle_material.size(),
                      "0 or " + std::to_string(triangles) + " entries, one per triangle");
  }
  return {};
}

Status check_vertex_indices(const character::Model& model) {
  const SkinnedMesh& mesh = model.mesh;
  const std::size_t vertices = mesh.vertex_count();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t index : mesh.triangles[t]) {
      if (index >= vertices) {
        return make_error(ErrorCode::kInvalidData, model.source,
                          "triangles[" + std::to_string(t) + "]", std::to_string(index),
                          "vertex index out of range (" + std::to_string(vertices) +
                              " vertices)");
      }
    }
  }
  return {};
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  const auto [low, high] = std::minmax(a, b);
  return (std::uint64_t{low} << 32) | high;
}

// Edge key -> edge id, open addressing with linear probing. A node-based
// std::unordered_map spends most of a level-4 subdivision allocating nodes;
// this flat table is sized once from the triangle count. Ids are handed out
// in insertion order, so the hash never shows in the result.
class EdgeIds {
 public:
  explicit EdgeIds(std::size_t max_edges) {
    std::size_t capacity = 16;
    while (capacity < 2 * max_edges) capacity *= 2;
    slots_.assign(capacity, Slot{kEmpty, 0});
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c /= 2) --shift_;
  }

  // The id of `key`, inserting it with id size() when new.
  std::pair<std::uint32_t, bool> find_or_insert(std::uint64_t key) {
    const std::size_t mask = slots_.size() - 1;
    // Fibonacci hashing: the top bits of key * 2^64/phi.
    std::size_t slot = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
    while (true) {
      Slot& s = slots_[slot];
      if (s.key == key) return {s.id, false};
      if (s.key == kEmpty) {
        s = Slot{key, size_};
        return {size_++, true};
      }
      slot = (slot + 1) & mask;
    }
  }

  std::uint32_t size() const { return size_; }

 private:
  // No real key: indices stay below 2^31, so a key's high half never is 2^32 - 1.
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  struct Slot {
    std::uint64_t key;
    std::uint32_t id;
  };
  std::vector<Slot> slots_;
  int shift_ = 0;
  std::uint32_t size_ = 0;
};

// The unique edges of a triangle list, in the contract's order (first met
// walking triangles in order, edges (v0,v1), (v1,v2), (v2,v0)), each
// with its endpoints in the direction it was first met, plus each triangle's
// three edge ids in that same local order.
struct EdgeTable {
  std::vector<std::array<std::uint32_t, 2>> endpoints;
  std::vector<std::array<std::uint32_t, 3>> triangle_edges;
};

// `max_edges` must bound the unique edges (the probe loop relies on a free
// slot); a tight bound keeps the table small and its probes in cache.
EdgeTable collect_edges(const std::vector<std::array<std::uint32_t, 3>>& triangles,
                        std::size_t max_edges) {
  EdgeTable table;
  table.triangle_edges.reserve(triangles.size());
  table.endpoints.reserve(max_edges);
  EdgeIds edge_ids(max_edges);
  for (const auto& corners : triangles) {
    std::array<std::uint32_t, 3> ids{};
    for (int side = 0; side < 3; ++side) {
      const std::uint32_t from = corners[static_cast<std::size_t>(side)];
      const std::uint32_t to = corners[static_cast<std::size_t>((side + 1) % 3)];
      const auto [id, inserted] = edge_ids.find_or_insert(edge_key(from, to));
      if (inserted) table.endpoints.push_back({from, to});
      ids[static_cast<std::size_t>(side)] = id;
    }
    table.triangle_edges.push_back(ids);
  }
  return table;
}

Vec3 average_normal(const Vec3& first, const Vec3& second) {
  const Vec3 sum = first + second;
  const float length = std::sqrt(sum.x * sum.x + sum.y * sum.y + sum.z * sum.z);
  // Opposite normals (a crease folded flat) have no average direction.
  if (!(length > 0.0f)) return first;
  return sum / length;
}

struct Influence {
  std::uint16_t joint;
  float weight;
};

// Heaviest first, ties by joint, so the kept set and the slot order are
// deterministic. Hand-rolled insertion sort: at most 2 * kMaxInfluences
// entries, and unlike std::sort it stays well-defined if a weight is NaN.
void sort_heaviest_first(Influence* influences, std::size_t count) {
  for (std::size_t i = 1; i < count; ++i) {
    const Influence moving = influences[i];
    std::size_t j = i;
    while (j > 0 && (influences[j - 1].weight < moving.weight ||
                     (influences[j - 1].weight == moving.weight && influences[j - 1].joint > moving.joint))) {
      influences[j] = influences[j - 1];
      --j;
    }
    influences[j] = moving;
  }
}

void add_influence(Influence* influences, std::size_t& count, std::uint16_t joint, float weight) {
  if (weight == 0.0f) return;
  for (std::size_t i = 0; i < count; ++i) {
    if (influences[i].joint == joint) {
      influences[i].weight += weight;
      return;
    }
  }
  influences[count++] = {joint, weight};
}

// The union of both endpoints' influences at half weight, the heaviest
// kMaxInfluences kept and renormalised; unused slots are joint 0 weight 0.
void merge_influences(const JointRow& joints_a, const WeightRow& weights_a, const JointRow& joints_b,
                      const WeightRow& weights_b, JointRow& joints_out, WeightRow& weights_out) {
  std::array<Influence, 2 * kMaxInfluences> influences{};
  std::size_t count = 0;
  for (std::size_t i = 0; i < kMaxInfluences; ++i) {
    add_influence(influences.data(), count, joints_a[i], 0.5f * weights_a[i]);
  }
  for (std::size_t i = 0; i < kMaxInfluences; ++i) {
    add_influence(influences.data(), count, joints_b[i], 0.5f * weights_b[i]);
  }
  sort_heaviest_first(influences.data(), count);
  const std::size_t kept = std::min<std::size_t>(count, kMaxInfluences);
  float total = 0.0f;
  for (std::size_t i = 0; i < kept; ++i) total += influences[i].weight;
  // Only valid rows (positive sums) are renormalised; anything else is
  // passed through rather than turned into NaNs.
  const float scale = total > 0.0f ? 1.0f / total : 1.0f;
  joints_out.fill(0);
  weights_out.fill(0.0f);
  for (std::size_t i = 0; i < kept; ++i) {
    joints_out[i] = influences[i].joint;
    weights_out[i] = influences[i].weight * scale;
  }
}

// Appends one vertex per edge, averaging the endpoints' attributes.
void append_midpoints(SkinnedMesh& mesh, const std::vector<std::array<std::uint32_t, 2>>& edges) {
  const bool has_normals = !mesh.normals.empty();
  const bool has_uvs = !mesh.uvs.empty();
  for (const auto& [a, b] : edges) {
    // Copies, not references: push_back may move the arrays' storage.
    const Vec3 position = (mesh.positions[a] + mesh.positions[b]) * 0.5f;
    mesh.positions.push_back(position);
    if (has_normals) {
      const Vec3 normal = average_normal(mesh.normals[a], mesh.normals[b]);
      mesh.normals.push_back(normal);
    }
    if (has_uvs) {
      const Vec2 uv = (mesh.uvs[a] + mesh.uvs[b]) * 0.5f;
      mesh.uvs.push_back(uv);
    }
    JointRow joints{};
    WeightRow weights{};
    merge_influences(mesh.joints[a], mesh.weights[a], mesh.joints[b], mesh.weights[b], joints,
                     weights);
    mesh.joints.push_back(joints);
    mesh.weights.push_back(weights);
  }
}

// One level in place: midpoints are appended after the existing vertices
// and triangle t is replaced by 4t .. 4t+3.
void subdivide_once(SkinnedMesh& mesh, std::size_t max_edges) {
  const std::uint32_t first_midpoint = static_cast<std::uint32_t>(mesh.vertex_count());
  const EdgeTable edges = collect_edges(mesh.triangles, max_edges);
  append_midpoints(mesh, edges.endpoints);

  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(mesh.triangles.size() * 4);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [v0, v1, v2] = mesh.triangles[t];
    const std::uint32_t m01 = first_midpoint + edges.triangle_edges[t][0];
    const std::uint32_t m12 = first_midpoint + edges.triangle_edges[t][1];
    const std::uint32_t m20 = first_midpoint + edges.triangle_edges[t][2];
    // Each child starts at its parent's corner (or, for the middle one, at
    // the midpoint of v0v1) and keeps the parent's winding.
    triangles.push_back({v0, m01, m20});
    triangles.push_back({m01, v1, m12});
    triangles.push_back({m20, m12, v2});
    triangles.push_back({m01, m12, m20});
  }
  mesh.triangles = std::move(triangles);

  if (!mesh.triangle_material.empty()) {
    std::vector<std::uint32_t> materials;
    materials.reserve(mesh.triangle_material.size() * 4);
    for (const std::uint32_t material : mesh.triangle_material) {
      materials.insert(materials.end(), 4, material);
    }
    mesh.triangle_material = std::move(materials);
  }
}

void reserve_vertices(SkinnedMesh& mesh, std::size_t vertices) {
  mesh.positions.reserve(vertices);
  if (!mesh.normals.empty()) mesh.normals.reserve(vertices);
  if (!mesh.uvs.empty()) mesh.uvs.reserve(vertices);
  mesh.joints.reserve(vertices);
  mesh.weights.reserve(vertices);
}

std::uint64_t count_unique_edges(const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  EdgeIds edge_ids(triangles.size() * 3);
  for (const auto& corners : triangles) {
    (void)edge_ids.find_or_insert(edge_key(corners[0], corners[1]));
    (void)edge_ids.find_or_insert(edge_key(corners[1], corners[2]));
    (void)edge_ids.find_or_insert(edge_key(corners[2], corners[0]));
  }
  return edge_ids.size();
}

Status too_large(const character::Model& model, int levels, std::uint64_t count, const char* what) {
  return make_error(ErrorCode::kLimitExceeded, model.source, "levels", std::to_string(levels),
                    "the result would have " + std::to_string(count) + " " + what +
                        ", more than 2^31");
}

}  // namespace

Expected<character::Model> subdivide(const character::Model& model, int levels) {
  if (levels < 0 || levels > kMaxSubdivisionLevels) {
    return invalid_argument("levels", std::to_string(levels),
                            "must be in [0, " + std::to_string(kMaxSubdivisionLevels) + "]");
  }
  SINEW_RETURN_IF_ERROR(check_vertex_indices(model));
  SINEW_RETURN_IF_ERROR(check_array_sizes(model));
  if (levels == 0) return model;

  // Triangles first: they need no edge count, and bounding them keeps the
  // edge count (at most 3T) and edge ids well inside 32 bits.
  const std::uint64_t output_triangles = std::uint64_t{model.mesh.triangle_count()} << (2 * levels);
  if (model.mesh.triangle_count() > kMaxElements || output_triangles > kMaxElements) {
    return too_large(model, levels, output_triangles, "triangles");
  }
  if (model.mesh.vertex_count() > kMaxElements) {
    return too_large(model, levels, model.mesh.vertex_count(), "vertices");
  }
  const MeshCounts input{model.mesh.vertex_count(), count_unique_edges(model.mesh.triangles),
                         model.mesh.triangle_count()};
  const MeshCounts output = counts_after(input, levels);
  if (output.vertices > kMaxElements) return too_large(model, levels, output.vertices, "vertices");

  character::Model result = model;
  result.source += " (subdivided " + std::to_string(levels) + ")";
  reserve_vertices(result.mesh, static_cast<std::size_t>(output.vertices));
  MeshCounts counts = input;
  for (int level = 0; level < levels; ++level) {
    // counts.edges bounds this level's unique edges (MeshCounts), as does 3T.
    subdivide_once(result.mesh, static_cast<std::size_t>(std::min(counts.edges, 3 * counts.triangles)));
    counts = counts_after(counts, 1);
  }
  return result;
}

}  // namespace sinew::editor
