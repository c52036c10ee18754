#include "runtime/jobs/job_system.h"

#include <algorithm>
#include <cstdlib>
#include <string_view>

#include <tbb/info.h>

namespace sinew {

int JobSystem::hardware_threads() { return std::max(1, tbb::info::default_concurrency()); }

const char* JobSystem::default_executor_name() {
  const char* env = std::getenv("SINEW_EXECUTOR");
  if (env != nullptr && std::string_view(env) == "threads") return "threads";
  if (env != nullptr && std::string_view(env) == "tbb") return "tbb";
#ifdef SINEW_DEFAULT_EXECUTOR_THREADS
  return "threads";
#else
  return "tbb";
#endif
}

JobSystem::JobSystem(int threads) : threads_(threads > 0 ? threads : hardware_threads()) {
  executor_ = std::string_view(default_executor_name()) == "threads" ? make_thread_pool_executor(threads_)
                                                                     : make_tbb_executor(threads_);
}

JobSystem::JobSystem(std::unique_ptr<Executor> executor)
    : threads_(executor ? executor->concurrency() : 1),
      executor_(executor ? std::move(executor) : make_thread_pool_executor(1)) {}

JobSystem::~JobSystem() = default;

void JobSystem::parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                             const std::function<void(Range)>& fn) {
  if (end <= begin) return;
  grain = std::max<std::size_t>(grain, 1);
  const std::size_t chunks = (end - begin + grain - 1) / grain;
  if (threads_ == 1 || chunks == 1) {
    // No arena hop for serial work: cheaper and trivially deterministic.
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::size_t b = begin + c * grain;
      fn(Range{b, std::min(end, b + grain)});
    }
    return;
  }
  // One task per chunk: every chunk is exactly the one the serial loop
  // above would produce, whatever the executor.
  executor_->run(chunks, [&](std::size_t c) {
    const std::size_t b = begin + c * grain;
    fn(Range{b, std::min(end, b + grain)});
  });
}

void JobSystem::parallel_for_tiles(int width, int height, int tile_size,
                                   const std::function<void(const Tile&)>& fn) {
  if (width <= 0 || height <= 0) return;
  tile_size = std::max(tile_size, 1);
  const int tiles_x = (width + tile_size - 1) / tile_size;
  const int tiles_y = (height + tile_size - 1) / tile_size;
  const auto count = static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);
  parallel_for(0, count, 1, [&](Range r) {
    for (std::size_t i = r.begin; i < r.end; ++i) {
      const int tx = static_cast<int>(i % static_cast<std::size_t>(tiles_x));
      const int ty = static_cast<int>(i / static_cast<std::size_t>(tiles_x));
      Tile tile;
      tile.x0 = tx * tile_size;
      tile.y0 = ty * tile_size;
      tile.x1 = std::min(width, tile.x0 + tile_size);
      tile.y1 = std::min(height, tile.y0 + tile_size);
      tile.index = static_cast<int>(i);
      fn(tile);
    }
  });
}

}  // namespace sinew
