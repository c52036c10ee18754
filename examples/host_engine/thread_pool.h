// The host's own worker threads, lent to Sinew through the callback task
// interface (sinew/tasks.h). A real engine would route run_batch into its
// job system; this is the smallest pool that honours the contract: run every
// index once, on any thread, and return only when all have finished.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include <sinew/sinew.h>

namespace host {

class ThreadPool {
 public:
  // `concurrency` threads run tasks: the caller of run() plus
  // concurrency - 1 workers.
  explicit ThreadPool(int concurrency);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  // Fork-join: task(context, i) for every i in [0, count).
  void run(std::uint32_t count, sinew::api::TaskFunction task, void* context);

  // What RayTracePass::execute takes; valid while the pool lives.
  sinew::api::TaskScheduler scheduler();

 private:
  void worker_loop();
  void work_on_current_batch();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable batch_posted_;
  std::condition_variable batch_done_;
  bool stopping_ = false;
  std::uint64_t generation_ = 0;  // bumped per batch, so workers see new work
  int workers_inside_ = 0;        // workers that may still touch the batch

  // The current batch (written under mutex_ while workers_inside_ == 0).
  sinew::api::TaskFunction task_ = nullptr;
  void* context_ = nullptr;
  std::uint32_t count_ = 0;
  std::atomic<std::uint32_t> next_index_{0};
  std::atomic<std::uint32_t> finished_{0};
};

}  // namespace host
