// JobSystem: data-parallel loops with an explicit thread count.
//
// Every program takes `--threads N` (default: all cores) and creates one
// JobSystem. Its tasks run on an Executor (runtime/jobs/executor.h): TBB in
// its own task_arena by default, so the count is exact and does not leak
// into a host engine's TBB usage; a std::thread pool when the environment
// says SINEW_EXECUTOR=threads or the build defines SINEW_DEFAULT_EXECUTOR_THREADS
// (the ThreadSanitizer preset); or a host's own scheduler. Work is split
// into chunks whose boundaries depend only on the range and the grain, never
// on timing or the executor, so per-chunk results are reproducible
// (docs/DESIGN.md section 4, determinism).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

#include "runtime/jobs/executor.h"

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
  // Runs on `executor` (a host's scheduler, or a specific back end).
  explicit JobSystem(std::unique_ptr<Executor> executor);
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

  // "tbb" or "threads": the executor JobSystem(int) picks.
  static const char* default_executor_name();

 private:
  int threads_ = 1;
  std::unique_ptr<Executor> executor_;
};

}  // namespace sinew
