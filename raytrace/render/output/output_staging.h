// A tile's outputs written into small planes of its own, then stored to the
// host's planes a row at a time with streaming (non-temporal) stores.
//
// Why: a frame's outputs are megabytes (16 MiB for colour, depth and two id
// planes at 1024x1024), far beyond the caches, and every line of them is
// written exactly once. Written in place, each 64-byte line is first read
// from memory (the store's read-for-ownership) and the shading of a 4x2
// block waits on eight such lines; the tile's rows are also scattered over
// one page per row and plane. Staged, the shading writes only lines in
// cache, and each row goes out as whole lines that memory takes without
// reading them first (docs/RAYTRACE.md, "Output staging"). Hosts get this for planes whose rows are 64-byte aligned.
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
