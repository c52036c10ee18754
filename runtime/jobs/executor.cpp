#include "runtime/jobs/executor.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

namespace sinew {
namespace {

class TbbExecutor final : public Executor {
 public:
  explicit TbbExecutor(int threads) : threads_(threads), arena_(threads) {}
  int concurrency() const override { return threads_; }
  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    // One task per index with a simple partitioner: nothing is merged or
    // split by timing.
    arena_.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, count, 1),
          [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) task(i);
          },
          tbb::simple_partitioner());
    });
  }

 private:
  int threads_;
  tbb::task_arena arena_;
};

// Workers sleep on a condition variable until a batch is posted, then
// claim task indices from an atomic counter alongside the calling thread.
class ThreadPoolExecutor final : public Executor {
 public:
  explicit ThreadPoolExecutor(int threads) : threads_(threads) {
    for (int i = 1; i < threads_; ++i) workers_.emplace_back([this] { work(); });
  }
  ~ThreadPoolExecutor() override {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }
  int concurrency() const override { return threads_; }

  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    // Nested (a task calling run), or a second caller while a batch runs:
    // run inline, which is always correct and cannot deadlock on a busy pool.
    const auto inline_run = [&] {
      for (std::size_t i = 0; i < count; ++i) task(i);
    };
    if (in_pool_task_ || workers_.empty()) return inline_run();
    std::unique_lock batch(batch_mutex_, std::try_to_lock);
    if (!batch.owns_lock()) return inline_run();
    {
      std::lock_guard lock(mutex_);
      task_ = &task;
      count_ = count;
      next_.store(0);
      active_ = workers_.size();
      ++generation_;
    }
    wake_.notify_all();
    drain();
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return active_ == 0; });
    task_ = nullptr;
  }

 private:
  void drain() {
    in_pool_task_ = true;
    for (std::size_t i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) (*task_)(i);
    in_pool_task_ = false;
  }

  void work() {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
        if (stopping_) return;
        seen = generation_;
      }
      drain();
      {
        std::lock_guard lock(mutex_);
        if (--active_ == 0) done_.notify_one();
      }
    }
  }

  const int threads_;
  std::vector<std::thread> workers_;
  std::mutex batch_mutex_;  // one batch at a time
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  bool stopping_ = false;
  std::uint64_t generation_ = 0;
  std::size_t active_ = 0;  // workers still draining the current batch
  const std::function<void(std::size_t)>* task_ = nullptr;
  std::size_t count_ = 0;
  std::atomic<std::size_t> next_{0};
  static thread_local bool in_pool_task_;
};

thread_local bool ThreadPoolExecutor::in_pool_task_ = false;

class CallbackExecutor final : public Executor {
 public:
  CallbackExecutor(int concurrency,
                   std::function<void(std::size_t, const std::function<void(std::size_t)>&)> submit_and_wait)
      : concurrency_(concurrency), submit_and_wait_(std::move(submit_and_wait)) {}
  int concurrency() const override { return concurrency_; }
  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    submit_and_wait_(count, task);
  }

 private:
  int concurrency_;
  std::function<void(std::size_t, const std::function<void(std::size_t)>&)> submit_and_wait_;
};

}  // namespace

std::unique_ptr<Executor> make_tbb_executor(int threads) {
  return std::make_unique<TbbExecutor>(std::max(1, threads));
}

std::unique_ptr<Executor> make_thread_pool_executor(int threads) {
  return std::make_unique<ThreadPoolExecutor>(std::max(1, threads));
}

std::unique_ptr<Executor> make_callback_executor(
    int concurrency,
    std::function<void(std::size_t, const std::function<void(std::size_t)>&)> submit_and_wait) {
  return std::make_unique<CallbackExecutor>(std::max(1, concurrency), std::move(submit_and_wait));
}

}  // namespace sinew
