#include "raytrace/render/output/output_staging.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "runtime/memory/streaming_stores.h"

namespace sinew::rt {
namespace {

// Bytes of one tile row of `plane`.
template <class T>
std::size_t row_bytes(const OutputPlane<T>& plane, const Tile& tile) {
  return static_cast<std::size_t>(tile.x1 - tile.x0) * plane.channels * sizeof(T);
}

// Rows that start on a line: only they leave whole lines to stream.
template <class T>
bool line_aligned(const OutputPlane<T>& plane) {
  return plane.wanted() && reinterpret_cast<std::uintptr_t>(plane.base) % kCacheLineBytes == 0 &&
         plane.pitch % kCacheLineBytes == 0;
}

template <class T>
void flush_plane(const OutputPlane<T>& staged, const OutputPlane<T>& out, const Tile& tile) {
  if (!staged.wanted() || staged.base == out.base) return;
  const std::size_t n = row_bytes(out, tile);
  for (int y = tile.y0; y < tile.y1; ++y) {
    stream_copy(reinterpret_cast<std::byte*>(out.at(tile.x0, y)),
               reinterpret_cast<const std::byte*>(staged.at(tile.x0, y)), n);
  }
}

}  // namespace

const OutputPlanes& OutputStaging::stage(const OutputPlanes& out, const Tile& tile) {
  tile_ = tile;
  const std::size_t rows = static_cast<std::size_t>(std::max(0, tile.y1 - tile.y0));
  const auto pitch_lines = [&](const auto& plane) { return (row_bytes(plane, tile) + kCacheLineBytes - 1) / kCacheLineBytes; };
  // Each staged plane's rows, rounded up to whole lines.
  std::size_t lines = 0;
  for_each_plane_pair(out, out, [&](const auto& plane, const auto&) {
    if (line_aligned(plane)) lines += pitch_lines(plane) * rows;
  });
  if (storage_.size() < lines * kCacheLineBytes) storage_.resize(lines * kCacheLineBytes);
  std::size_t next = 0;
  for_each_plane_pair(out, staged_, [&](const auto& plane, auto& staged) {
    staged = {};
    if (!plane.wanted()) return;
    if (!line_aligned(plane)) {
      staged = plane;  // written in place
      return;
    }
    staged.base = storage_.data() + next * kCacheLineBytes;
    staged.pitch = pitch_lines(plane) * kCacheLineBytes;
    staged.channels = plane.channels;
    staged.x0 = tile.x0;
    staged.y0 = tile.y0;
    next += pitch_lines(plane) * rows;
  });
  return staged_;
}

void OutputStaging::flush(const OutputPlanes& out) const {
  for_each_plane_pair(staged_, out, [&](const auto& staged, const auto& plane) { flush_plane(staged, plane, tile_); });
  stream_fence();
}

}  // namespace sinew::rt
