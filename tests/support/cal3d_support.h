// Helpers for code that drives the Cal3D library directly (oracle tests and
// the benchmark's Cal3D column).
#pragma once

#include <cal3d/cal3d.h>
#include <cal3d/coretrack.h>

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

}  // namespace sinew::testing_support
