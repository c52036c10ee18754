#include "thread_pool.h"

#include <algorithm>

namespace host {
namespace {

// Set while a thread runs one of the pool's tasks: a task that submits a
// batch of its own (nested parallelism) then runs it inline, which tasks.h
// allows, instead of waiting on workers that may all be busy with the outer
// batch.
thread_local bool t_running_task = false;

}  // namespace

ThreadPool::ThreadPool(int concurrency) {
  const int threads = std::max(1, concurrency);
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  batch_posted_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

sinew::api::TaskScheduler ThreadPool::scheduler() {
  sinew::api::TaskScheduler s;
  s.concurrency = static_cast<int>(workers_.size()) + 1;
  s.user = this;
  s.run_batch = [](void* user, std::uint32_t count, sinew::api::TaskFunction task, void* context) {
    static_cast<ThreadPool*>(user)->run(count, task, context);
  };
  return s;
}

void ThreadPool::run(std::uint32_t count, sinew::api::TaskFunction task, void* context) {
  if (count == 0) return;
  if (t_running_task || workers_.empty()) {
    for (std::uint32_t i = 0; i < count; ++i) task(context, i);
    return;
  }
  {
    std::unique_lock lock(mutex_);
    // A worker that woke late for the previous batch may still be reading
    // its fields: let it leave before they are overwritten.
    batch_done_.wait(lock, [this] { return workers_inside_ == 0; });
    task_ = task;
    context_ = context;
    count_ = count;
    next_index_.store(0);
    finished_.store(0);
    ++generation_;
  }
  batch_posted_.notify_all();
  work_on_current_batch();  // the caller works too rather than idling
  std::unique_lock lock(mutex_);
  batch_done_.wait(lock, [this] { return finished_.load() == count_ && workers_inside_ == 0; });
}

void ThreadPool::worker_loop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      batch_posted_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
      ++workers_inside_;
    }
    work_on_current_batch();
    {
      std::lock_guard lock(mutex_);
      --workers_inside_;
    }
    batch_done_.notify_all();
  }
}

void ThreadPool::work_on_current_batch() {
  t_running_task = true;
  for (std::uint32_t i = next_index_.fetch_add(1); i < count_; i = next_index_.fetch_add(1)) {
    task_(context_, i);
    if (finished_.fetch_add(1) + 1 == count_) {
      // Taking the lock orders this with the caller's wait: no lost wake-up.
      std::lock_guard lock(mutex_);
      batch_done_.notify_all();
    }
  }
  t_running_task = false;
}

}  // namespace host
