// A tile's outputs written into small planes of its own, then stored to the
// host's planes a row at a time with streaming (non-temporal) stores: a
// frame's outputs far exceed the caches and each line is written once, so
// in place every store would first read its line from memory. Hosts get this
// for planes whose rows are 64-byte aligned. docs/RAYTRACE.md, "Output
// staging".
#pragma once

#include <cstddef>

#include "raytrace/render/output/output_planes.h"
#include "runtime/jobs/job_system.h"
#include "runtime/memory/line_aligned.h"

namespace sinew::rt {

class OutputStaging {
 public:
  // Planes for `tile`: for each wanted plane of `out` whose rows start on
  // 64-byte lines (base and pitch multiples of 64), a staging plane with
  // the same channels; the other wanted planes as they are (written in
  // place: streaming part of a line costs more than the store it saves).
  const OutputPlanes& stage(const OutputPlanes& out, const Tile& tile);
  // Stores every staged row into the planes stage() was given. The streaming
  // stores are fenced before it returns, so whatever the caller does next
  // to publish the frame (a job's completion) publishes them too.
  void flush(const OutputPlanes& out) const;

 private:
  LineAlignedVector<std::byte> storage_;  // the staging planes, each starting on a line
  OutputPlanes staged_;
  Tile tile_;
};

}  // namespace sinew::rt
