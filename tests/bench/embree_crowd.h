// The Embree peer of `sinew-bench queries`: a crowd of one character, every
// instance its own Embree geometry, skinned in full every tick with Sinew's
// own skinning kernel (rt::skin_vertices, no escape check) from the same
// skinning matrices Sinew is given, then refitted or rebuilt
// (EmbreeTracer), and queried one ray at a time with rtcIntersect1.
//
// Only built where Embree was found (SINEW_HAVE_EMBREE).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "raytrace/skinning/packed_influences.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"
#include "runtime/math/ray.h"
#include "runtime/mesh/skinned_mesh.h"
#include "tests/bench/embree_tracer.h"

namespace sinew {
class JobSystem;
}

namespace sinew::bench {

// One tick's update, in milliseconds.
struct EmbreeCrowdUpdate {
  double skin_ms = 0.0;   // every vertex of every instance
  double build_ms = 0.0;  // vertex upload + rtcCommitScene (refit or rebuild)
};

class EmbreeCrowd {
 public:
  // `mesh` must outlive the crowd. `ids`: the id each instance's hits
  // report, one per instance. `threads`: the Embree device's build threads.
  static Expected<std::unique_ptr<EmbreeCrowd>> create(EmbreeMode mode, int threads, const SkinnedMesh& mesh,
                                                       std::span<const std::uint32_t> ids);

  // Skins every instance with its matrices (bones[i]: bind pose -> world,
  // one per joint) on `jobs`, then brings the BVH up to date (the first
  // call builds it).
  Expected<EmbreeCrowdUpdate> update(std::span<const std::vector<Affine3>> bones, JobSystem& jobs);

  // rays[i] -> hits[i] (same sizes), rtcIntersect1 each, on the calling
  // thread.
  void trace(std::span<const Ray> rays, std::span<Hit> hits) const;

 private:
  EmbreeCrowd(std::unique_ptr<EmbreeTracer> tracer, const SkinnedMesh& mesh, std::span<const std::uint32_t> ids);

  std::unique_ptr<EmbreeTracer> tracer_;
  const SkinnedMesh* mesh_;
  rt::PackedInfluences influences_;  // packed once, as Sinew does per character
  std::vector<std::uint32_t> ids_;
  std::vector<std::vector<Vec3>> positions_;  // per instance, this tick's skinned vertices
};

}  // namespace sinew::bench
