// One tile's working set, reused by each thread across tiles and frames:
// the tile's hits, primary directions and surfaces stay in cache from the
// primary rays through the shadow rays to the shading. Shared by the
// renderer and by tracers that stand in for it (the Embree peer of the
// benchmarks), which run on the same per-tile schedule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "raytrace/render/renderer.h"
#include "runtime/math/types.h"

namespace sinew::rt {

struct TileScratch {
  std::vector<Hit> hits;
  std::vector<Vec3> directions;  // unit primary directions
  std::vector<SurfacePoint> surfaces;
  std::vector<std::uint8_t> lit;  // bit l: light l reaches the hit
  void resize(std::size_t n) {
    if (hits.size() < n) {
      hits.resize(n);
      directions.resize(n);
      surfaces.resize(n);
      lit.resize(n);
    }
  }
};

// The calling thread's scratch. One tile at a time per thread: a tile's
// work never starts another tile's on the same thread.
inline TileScratch& tile_scratch() {
  thread_local TileScratch scratch;
  return scratch;
}

}  // namespace sinew::rt
