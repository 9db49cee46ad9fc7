// The threads an occlusion buffer owns (src/core/worker_pool.hpp).
#include "core/worker_pool.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

using occull::detail::WorkerPool;

// Each run calls the job once on every lane, lane 0 on the caller's thread,
// and returns only when all calls have: what they wrote is there to read,
// run after run (a worker that missed a run, or a run returning early,
// leaves a lane's count behind).
TEST(WorkerPool, RunsTheJobOnceOnEveryLaneAndReturnsWhenAllHave) {
  for (const int workers : {0, 1, 3}) {
    WorkerPool pool(workers);
    ASSERT_EQ(pool.lanes(), workers + 1);
    std::vector<long> calls(std::size_t(pool.lanes()), 0);
    std::vector<std::thread::id> ids(calls.size());
    for (int run = 1; run <= 2000; ++run) {
      auto job = [&](int lane) {
        ++calls[std::size_t(lane)];
        ids[std::size_t(lane)] = std::this_thread::get_id();
      };
      pool.run(job);
      for (std::size_t lane = 0; lane < calls.size(); ++lane) ASSERT_EQ(calls[lane], run) << "lane " << lane;
    }
    EXPECT_EQ(ids[0], std::this_thread::get_id());
    for (std::size_t lane = 1; lane < ids.size(); ++lane) EXPECT_NE(ids[lane], std::this_thread::get_id());
  }
}
