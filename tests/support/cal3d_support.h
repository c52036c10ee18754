// Helpers for code that drives the Cal3D library directly (oracle tests and
// the benchmark's Cal3D column).
#pragma once

#include <cal3d/cal3d.h>
#include <cal3d/coretrack.h>

#include <algorithm>
#include <optional>
#include <span>
#include <vector>

#include "runtime/math/types.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::testing_support {

// Cal3D 0.11's ~CalCoreAnimation does not free its tracks; call this before
// a CalCoreModel is destroyed so LeakSanitizer stays quiet.
inline void free_cal3d_animation_tracks(CalCoreModel& core) {
  for (int i = 0; i < core.getCoreAnimationCount(); ++i) {
    if (CalCoreAnimation* anim = core.getCoreAnimation(i)) {
      for (CalCoreTrack* track : anim->getListCoreTrack()) {
        track->destroy();
        delete track;
      }
      anim->getListCoreTrack().clear();
    }
  }
}

// The length of the rest mesh's bounding-box diagonal: the "model size" that
// oracle tolerances are relative to.
inline double bbox_diagonal(const SkinnedMesh& mesh) {
  Vec3 lo(1e30f), hi(-1e30f);
  for (const Vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return static_cast<double>(glm::length(hi - lo));
}

// Skins every submesh of `model`'s meshes (in `mesh_ids` order, submeshes in
// file order: the importer's vertex order) with Cal3D's own physique and
// returns the largest distance to `ours`, divided by `scale`; nullopt when
// the vertex counts differ.
inline std::optional<double> max_vertex_error_vs_cal3d(CalModel& model, std::span<const int> mesh_ids,
                                                       std::span<const Vec3> ours, double scale) {
  std::vector<float> cal_vertices;
  std::size_t base = 0;
  double worst = 0.0;
  for (int id : mesh_ids) {
    for (CalSubmesh* sub : model.getMesh(id)->getVectorSubmesh()) {
      const auto n = static_cast<std::size_t>(sub->getVertexCount());
      if (base + n > ours.size()) return std::nullopt;
      cal_vertices.assign(n * 3, 0.0f);
      if (model.getPhysique()->calculateVertices(sub, cal_vertices.data()) != static_cast<int>(n)) {
        return std::nullopt;
      }
      for (std::size_t v = 0; v < n; ++v) {
        const Vec3 c(cal_vertices[v * 3], cal_vertices[v * 3 + 1], cal_vertices[v * 3 + 2]);
        worst = std::max(worst, static_cast<double>(glm::length(ours[base + v] - c)) / scale);
      }
      base += n;
    }
  }
  if (base != ours.size()) return std::nullopt;
  return worst;
}

}  // namespace sinew::testing_support
