#include "tests/bench/embree_crowd.h"

#include <chrono>
#include <string>

#include "raytrace/skinning/skinning.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/stopwatch.h"

namespace sinew::bench {

Expected<std::unique_ptr<EmbreeCrowd>> EmbreeCrowd::create(EmbreeMode mode, int threads, const SkinnedMesh& mesh,
                                                           std::span<const std::uint32_t> ids) {
  SINEW_ASSIGN_OR_RETURN(std::unique_ptr<EmbreeTracer> tracer, EmbreeTracer::create(mode, threads));
  return std::unique_ptr<EmbreeCrowd>(new EmbreeCrowd(std::move(tracer), mesh, ids));
}

EmbreeCrowd::EmbreeCrowd(std::unique_ptr<EmbreeTracer> tracer, const SkinnedMesh& mesh,
                         std::span<const std::uint32_t> ids)
    : tracer_(std::move(tracer)),
      mesh_(&mesh),
      influences_(rt::pack_influences(mesh)),
      ids_(ids.begin(), ids.end()),
      positions_(ids.size(), std::vector<Vec3>(mesh.vertex_count())) {}

Expected<EmbreeCrowdUpdate> EmbreeCrowd::update(std::span<const std::vector<Affine3>> bones, JobSystem& jobs) {
  if (bones.size() != positions_.size()) {
    return invalid_argument("bones", std::to_string(bones.size()),
                            "expected one set of matrices per instance (" + std::to_string(positions_.size()) + ")");
  }
  EmbreeCrowdUpdate times;
  // Instances are spread over the threads whole (a character is a few
  // thousand vertices: splitting one would cost more than it saves).
  const auto skin_start = std::chrono::steady_clock::now();
  jobs.parallel_for(0, positions_.size(), 1, [&](Range range) {
    for (std::size_t i = range.begin; i < range.end; ++i) {
      rt::SkinningTargets targets;
      targets.positions = positions_[i];
      rt::skin_vertices(*mesh_, influences_, bones[i], targets, nullptr, nullptr);
    }
  });
  times.skin_ms = ms_since(skin_start);
  std::vector<EmbreeMesh> meshes(positions_.size());
  for (std::size_t i = 0; i < meshes.size(); ++i) meshes[i] = {mesh_->triangles, positions_[i], ids_[i]};
  SINEW_ASSIGN_OR_RETURN(times.build_ms, tracer_->update(meshes));
  return times;
}

void EmbreeCrowd::trace(std::span<const Ray> rays, std::span<Hit> hits) const {
  for (std::size_t i = 0; i < rays.size() && i < hits.size(); ++i) hits[i] = tracer_->intersect1(rays[i]);
}

}  // namespace sinew::bench
