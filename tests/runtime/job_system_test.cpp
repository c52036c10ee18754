#include <gtest/gtest.h>

#include <atomic>
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

}  // namespace
}  // namespace sinew
