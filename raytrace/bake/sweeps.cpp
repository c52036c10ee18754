// Sample sweeps (fuzzy bake, bake_steps.h): the samples skinned batch by
// batch into a chunk of bones' vertex boxes, and each triangle's best bone
// among the chunk's candidates.
#include <algorithm>

#include "raytrace/bake/bake_steps.h"
#include "raytrace/skinning/skinning.h"

namespace sinew::rt::bake_detail {
namespace {

// The part of a sorted bone list inside [first, last).
std::span<const std::uint16_t> within(std::span<const std::uint16_t> list, std::uint32_t first,
                                      std::uint32_t last) {
  const auto lo = std::lower_bound(list.begin(), list.end(), first);
  const auto hi = std::lower_bound(lo, list.end(), last);
  return list.subspan(static_cast<std::size_t>(lo - list.begin()),
                      static_cast<std::size_t>(hi - lo));
}

}  // namespace

Status sweep_samples(const Samples& samples, JobSystem& jobs, Progress& progress, std::string_view phase,
                     const std::function<void(Range, std::size_t, std::size_t)>& grow) {
  const std::size_t count = samples.count();
  const std::size_t vertex_count = samples.mesh.vertex_count();
  for (std::size_t s0 = 0; s0 < count; s0 += kSamplesPerBatch) {
    const std::size_t s1 = std::min(count, s0 + kSamplesPerBatch);
    jobs.parallel_for(0, vertex_count, kVertexGrain, [&](Range r) { grow(r, s0, s1); });
    SINEW_RETURN_IF_ERROR(progress.advance(phase, static_cast<double>(s1 - s0)));
  }
  return {};
}

Status grow_chunk_boxes(const Samples& samples, const BoneLists& needs, BoxChunk& chunk, float pad,
                        JobSystem& jobs, Progress& progress) {
  std::fill(chunk.boxes.begin(), chunk.boxes.end(), Aabb::empty());
  SINEW_RETURN_IF_ERROR(sweep_samples(samples, jobs, progress, "sampling", [&](Range r, std::size_t s0, std::size_t s1) {
    for (std::size_t v = r.begin; v < r.end; ++v) {
      const auto bones = within(needs.of(v), chunk.first, chunk.last);
      if (bones.empty()) continue;
      Aabb* boxes = &chunk.at(v, chunk.first);
      for (std::size_t s = s0; s < s1; ++s) {
        const Vec3 p = skin_point(samples.mesh, v, samples.pose(s));
        const Affine3* bone_from_pose = samples.bone_from_pose(s);
        for (std::uint16_t b : bones) boxes[b - chunk.first].extend(bone_from_pose[b].transform_point(p));
      }
    }
  }));
  jobs.parallel_for(0, chunk.boxes.size(), kVertexGrain * 4, [&](Range r) {
    for (std::size_t i = r.begin; i < r.end; ++i) pad_box(chunk.boxes[i], pad);
  });
  return {};
}

// Candidates are visited in increasing bone order (chunks in order, sorted
// lists within), so the strict comparison leaves ties with the lowest bone.
void assign_chunk(const SkinnedMesh& mesh, const BoneLists& candidates, const BoxChunk& chunk,
                  Assignment& best, JobSystem& jobs) {
  jobs.parallel_for(0, mesh.triangle_count(), kTriangleGrain, [&](Range r) {
    for (std::size_t t = r.begin; t < r.end; ++t) {
      const auto& tri = mesh.triangles[t];
      for (std::uint16_t b : within(candidates.of(t), chunk.first, chunk.last)) {
        Aabb box = chunk.at(tri[0], b);
        box.extend(chunk.at(tri[1], b));
        box.extend(chunk.at(tri[2], b));
        const double area = surface_area_d(box);
        if (area < best.area[t]) {
          best.area[t] = area;
          best.bone[t] = b;
        }
      }
    }
  });
}

}  // namespace sinew::rt::bake_detail
