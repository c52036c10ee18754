// JobSystem: data-parallel loops on TBB with an explicit thread count.
//
// Every program takes `--threads N` (default: all cores) and creates one
// JobSystem; work runs inside its own tbb::task_arena so the count is exact
// and does not leak into a host engine's TBB usage. Work is split into
// chunks whose boundaries depend only on the range and the grain, never on
// timing, so per-chunk results are reproducible (DESIGN.md section 4,
// determinism).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace sinew {

struct Range {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t size() const { return end - begin; }
};

// One image tile: pixels [x0, x1) x [y0, y1).
struct Tile {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
  int index = 0;  // row-major tile number, stable across runs
};

class JobSystem {
 public:
  // threads <= 0 means every core the process may use.
  explicit JobSystem(int threads = 0);
  ~JobSystem();
  JobSystem(const JobSystem&) = delete;
  JobSystem& operator=(const JobSystem&) = delete;

  int thread_count() const { return threads_; }

  // Calls fn on disjoint chunks covering [begin, end), each at most `grain`
  // long (the last may be shorter). Blocks until all chunks are done.
  void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                    const std::function<void(Range)>& fn);

  // Splits a width x height image into tile x tile squares and calls fn on
  // each, in parallel.
  void parallel_for_tiles(int width, int height, int tile_size,
                          const std::function<void(const Tile&)>& fn);

  // The number of cores available to this process.
  static int hardware_threads();

 private:
  struct Arena;
  int threads_ = 1;
  std::unique_ptr<Arena> arena_;
};

}  // namespace sinew
