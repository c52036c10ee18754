// Escape checks (fuzzy bake, bake_steps.h): per vertex a check in each bone
// its triangles were given, the checks' boxes over every sample, and each
// triangle's fuzzy box as the union of its corners' checks.
#include <algorithm>

#include "raytrace/bake/bake_steps.h"
#include "raytrace/skinning/skinning.h"

namespace sinew::rt::bake_detail {

void make_vertex_checks(const VertexTriangles& adj, std::span<const std::uint16_t> triangle_bone,
                        std::size_t vertex_count, FuzzyCharacterData& out) {
  out.vertex_check_begin.assign(1, 0);
  out.vertex_check_begin.reserve(vertex_count + 1);
  std::vector<std::uint16_t> scratch;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    scratch.clear();
    for (std::uint32_t t : adj.of(v)) scratch.push_back(triangle_bone[t]);
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    for (std::uint16_t b : scratch) out.vertex_checks.push_back({b, Aabb::empty()});
    out.vertex_check_begin.push_back(static_cast<std::uint32_t>(out.vertex_checks.size()));
  }
}

Status grow_check_boxes(const Samples& samples, float pad, JobSystem& jobs, Progress& progress,
                        FuzzyCharacterData& out) {
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, "checks", [&](Range r, std::size_t s0, std::size_t s1) {
    for (std::size_t v = r.begin; v < r.end; ++v) {
      VertexCheck* first = out.vertex_checks.data() + out.vertex_check_begin[v];
      VertexCheck* last = out.vertex_checks.data() + out.vertex_check_begin[v + 1];
      if (first == last) continue;
      for (std::size_t s = s0; s < s1; ++s) {
        const Vec3 p = skin_point(samples.mesh, v, samples.pose(s));
        const Affine3* bone_from_pose = samples.bone_from_pose(s);
        for (VertexCheck* c = first; c != last; ++c) c->box.extend(bone_from_pose[c->bone].transform_point(p));
      }
    }
  }));
  for (VertexCheck& c : out.vertex_checks) pad_box(c.box, pad);
  return {};
}

void link_triangle_checks(const SkinnedMesh& mesh, FuzzyCharacterData& out) {
  out.triangle_checks.resize(mesh.triangle_count());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint16_t bone = out.triangle_bone[t];
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.triangles[t][i];
      const auto first = out.vertex_checks.begin() + out.vertex_check_begin[v];
      const auto last = out.vertex_checks.begin() + out.vertex_check_begin[v + 1];
      const auto it = std::lower_bound(first, last, bone,
                                       [](const VertexCheck& c, std::uint16_t b) { return c.bone < b; });
      out.triangle_checks[t][i] = static_cast<std::uint32_t>(it - out.vertex_checks.begin());
    }
  }
}

std::vector<Aabb> triangle_fuzzy_boxes(const FuzzyCharacterData& out) {
  std::vector<Aabb> boxes(out.triangle_checks.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) {
    for (std::uint32_t c : out.triangle_checks[t]) boxes[t].extend(out.vertex_checks[c].box);
  }
  return boxes;
}

}  // namespace sinew::rt::bake_detail
