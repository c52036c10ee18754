// Executor: where a JobSystem's tasks run. TBB by default; a plain pool of
// std::threads (for ThreadSanitizer builds, whose happens-before tracking
// cannot see inside the uninstrumented system TBB, and for hosts without
// TBB); or a host engine's own scheduler through one callback, so Sinew's
// work runs on the host's thread pool (docs/EMBEDDING.md).
//
// The contract is one call: run `count` independent tasks, each exactly
// once, possibly in parallel, and return when all have returned. Tasks
// never throw. A task may itself call run() (nested parallelism): an
// executor may then run the inner tasks on the calling thread.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace sinew {

class Executor {
 public:
  virtual ~Executor() = default;
  // How many tasks may run at once (the JobSystem's thread count).
  virtual int concurrency() const = 0;
  virtual void run(std::size_t count, const std::function<void(std::size_t)>& task) = 0;
};

// TBB in its own task_arena of exactly `threads` threads (so a host's own
// TBB use is unaffected).
std::unique_ptr<Executor> make_tbb_executor(int threads);

// `threads` - 1 std::threads plus the calling thread, sharing tasks through
// an atomic counter; synchronised with a mutex and condition variables.
std::unique_ptr<Executor> make_thread_pool_executor(int threads);

// A host's scheduler: `submit_and_wait(count, task)` must call task(i) once
// for every i in [0, count), on any threads, and return when all are done.
std::unique_ptr<Executor> make_callback_executor(
    int concurrency, std::function<void(std::size_t count, const std::function<void(std::size_t)>& task)>
                         submit_and_wait);

}  // namespace sinew
