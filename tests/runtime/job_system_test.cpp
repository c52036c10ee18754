#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "runtime/jobs/job_system.h"

namespace sinew {
namespace {

TEST(JobSystem, ThreadCountIsHonoured) {
  EXPECT_EQ(JobSystem(1).thread_count(), 1);
  EXPECT_EQ(JobSystem(3).thread_count(), 3);
  EXPECT_EQ(JobSystem(0).thread_count(), JobSystem::hardware_threads());
}

TEST(JobSystem, ParallelForCoversEveryIndexOnce) {
  for (int threads : {1, 2, 4}) {
    JobSystem jobs(threads);
    std::vector<std::atomic<int>> hits(10007);
    jobs.parallel_for(0, hits.size(), 64, [&](Range r) {
      EXPECT_LE(r.size(), 64u);
      for (std::size_t i = r.begin; i < r.end; ++i) hits[i].fetch_add(1);
    });
    for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << i;
  }
}

TEST(JobSystem, ChunksAreIndependentOfThreadCount) {
  auto chunks_for = [](int threads) {
    JobSystem jobs(threads);
    std::mutex m;
    std::set<std::pair<std::size_t, std::size_t>> chunks;
    jobs.parallel_for(5, 1000, 37, [&](Range r) {
      std::lock_guard lock(m);
      chunks.insert({r.begin, r.end});
    });
    return chunks;
  };
  EXPECT_EQ(chunks_for(1), chunks_for(2));
  EXPECT_EQ(chunks_for(1), chunks_for(4));
}

TEST(JobSystem, UsesNoMoreThreadsThanAsked) {
  JobSystem jobs(2);
  std::mutex m;
  std::set<std::thread::id> ids;
  jobs.parallel_for(0, 256, 1, [&](Range) {
    std::lock_guard lock(m);
    ids.insert(std::this_thread::get_id());
  });
  EXPECT_LE(ids.size(), 2u);
}

TEST(JobSystem, TilesCoverTheImageExactlyOnce) {
  JobSystem jobs(2);
  const int w = 100, h = 37;
  std::vector<std::atomic<int>> hits(static_cast<std::size_t>(w * h));
  std::atomic<int> tiles{0};
  jobs.parallel_for_tiles(w, h, 16, [&](const Tile& t) {
    tiles.fetch_add(1);
    EXPECT_LE(t.x1 - t.x0, 16);
    EXPECT_LE(t.y1 - t.y0, 16);
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) hits[static_cast<std::size_t>(y * w + x)].fetch_add(1);
  });
  EXPECT_EQ(tiles.load(), 7 * 3);
  for (auto& h1 : hits) ASSERT_EQ(h1.load(), 1);
}

TEST(JobSystem, EmptyRangesDoNothing) {
  JobSystem jobs(2);
  int calls = 0;
  jobs.parallel_for(10, 10, 4, [&](Range) { ++calls; });
  jobs.parallel_for(10, 3, 4, [&](Range) { ++calls; });
  jobs.parallel_for_tiles(0, 10, 8, [&](const Tile&) { ++calls; });
  EXPECT_EQ(calls, 0);
}

// Every executor runs every task exactly once, in parallel where it can,
// and JobSystem's chunks do not depend on which one runs them.
std::unique_ptr<Executor> make_executor(const std::string& kind, int threads) {
  if (kind == "tbb") return make_tbb_executor(threads);
  if (kind == "threads") return make_thread_pool_executor(threads);
  // A host's scheduler: here, std::async per task, as a stand-in for an
  // engine's pool (the test of the callback path, not of a real engine).
  return make_callback_executor(threads, [](std::size_t count, const std::function<void(std::size_t)>& task) {
    std::vector<std::thread> pool;
    std::atomic<std::size_t> next{0};
    for (int t = 0; t < 3; ++t) {
      pool.emplace_back([&] {
        for (std::size_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) task(i);
      });
    }
    for (std::thread& th : pool) th.join();
  });
}

class Executors : public testing::TestWithParam<std::string> {};

TEST_P(Executors, RunEveryTaskExactlyOnce) {
  for (int threads : {1, 2, 4}) {
    JobSystem jobs(make_executor(GetParam(), threads));
    EXPECT_EQ(jobs.thread_count(), threads);
    for (int repeat = 0; repeat < 20; ++repeat) {  // batches back to back reuse the pool
      std::vector<std::atomic<int>> hits(5003);
      jobs.parallel_for(0, hits.size(), 7, [&](Range r) {
        for (std::size_t i = r.begin; i < r.end; ++i) hits[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << i;
    }
  }
}

TEST_P(Executors, NestedLoopsCompleteAndCoverEverything) {
  JobSystem jobs(make_executor(GetParam(), 3));
  std::vector<std::atomic<int>> hits(64 * 64);
  jobs.parallel_for(0, 64, 1, [&](Range outer) {
    jobs.parallel_for(0, 64, 5, [&](Range inner) {
      for (std::size_t i = inner.begin; i < inner.end; ++i) hits[outer.begin * 64 + i].fetch_add(1);
    });
  });
  for (auto& h : hits) ASSERT_EQ(h.load(), 1);
}

TEST_P(Executors, ResultsMatchTheSerialLoop) {
  // A per-chunk reduction written to per-chunk slots: identical whatever runs it.
  auto sums = [&](JobSystem& jobs) {
    std::vector<double> out(100, 0.0);
    jobs.parallel_for(0, 100 * 97, 97, [&](Range r) {
      double s = 0.0;
      for (std::size_t i = r.begin; i < r.end; ++i) s += 1.0 / static_cast<double>(i + 1);
      out[r.begin / 97] = s;
    });
    return out;
  };
  JobSystem serial(1);
  JobSystem parallel(make_executor(GetParam(), 4));
  EXPECT_EQ(sums(serial), sums(parallel));
}

// ThreadSanitizer cannot see the synchronisation inside the system's
// uninstrumented TBB, so a TSan build tests the executors it can see (its
// JobSystem runs on the thread pool).
std::vector<std::string> executors_to_test() {
#if defined(__SANITIZE_THREAD__)
  return {"threads", "callback"};
#else
  return {"tbb", "threads", "callback"};
#endif
}

INSTANTIATE_TEST_SUITE_P(All, Executors, testing::ValuesIn(executors_to_test()));

TEST(JobSystem, TheEnvironmentPicksTheThreadPool) {
  ASSERT_EQ(setenv("SINEW_EXECUTOR", "threads", 1), 0);
  EXPECT_STREQ(JobSystem::default_executor_name(), "threads");
  ASSERT_EQ(setenv("SINEW_EXECUTOR", "tbb", 1), 0);
  EXPECT_STREQ(JobSystem::default_executor_name(), "tbb");
  unsetenv("SINEW_EXECUTOR");
}

}  // namespace
}  // namespace sinew
