// run_jobs (app/jobs.hpp): every job runs once, `finished` comes in index order whatever the
// scheduling, failures are returned at their index, and stop_after_failure skips only later
// indices, so the first failure is the serial run's.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "extwrench/app/jobs.hpp"

namespace extwrench {
namespace {

TEST(Jobs, EveryJobRunsOnceAndFinishedComesInIndexOrder) {
  for (const int threads : {1, 2, 5}) {
    constexpr std::size_t kCount = 12;
    std::vector<std::atomic<int>> runs(kCount);
    std::vector<std::size_t> order;
    const JobOutcomes out = run_jobs(
        kCount,
        [&](std::size_t i) {
          // Early jobs take longest, so that later ones end first when run in parallel.
          std::this_thread::sleep_for(std::chrono::milliseconds(2 * (kCount - i)));
          ++runs[i];
        },
        {.jobs = threads}, [&](std::size_t i) { order.push_back(i); });
    for (std::size_t i = 0; i < kCount; ++i) {
      EXPECT_EQ(runs[i].load(), 1) << i;
      ASSERT_LT(i, order.size());
      EXPECT_EQ(order[i], i);
      EXPECT_FALSE(out.errors[i]);
      EXPECT_FALSE(out.skipped[i]);
    }
    EXPECT_EQ(out.first_failure(), kCount);
  }
}

TEST(Jobs, FailuresAreReturnedAtTheirIndexAndStopSkipsOnlyLaterJobs) {
  for (const bool stop : {false, true}) {
    for (const int threads : {1, 3}) {
      std::vector<std::atomic<int>> runs(10);
      const JobOutcomes out =
          run_jobs(10,
                   [&](std::size_t i) {
                     ++runs[i];
                     if (i == 6) std::this_thread::sleep_for(std::chrono::milliseconds(30));
                     if (i == 3 || i == 6) throw std::runtime_error("job " + std::to_string(i));
                   },
                   {.jobs = threads, .stop_after_failure = stop});
      EXPECT_EQ(out.first_failure(), 3u);
      ASSERT_TRUE(out.errors[3]);
      try {
        std::rethrow_exception(out.errors[3]);
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "job 3");
      }
      for (std::size_t i = 0; i <= 3; ++i) EXPECT_EQ(runs[i].load(), 1) << i;
      for (std::size_t i = 0; i < 10; ++i) {
        EXPECT_EQ(out.skipped[i], runs[i].load() == 0) << i;
        if (!stop) {
          EXPECT_EQ(runs[i].load(), 1) << i;
        }
        if (stop && threads == 1 && i > 3) {
          EXPECT_TRUE(out.skipped[i]) << i;
        }
      }
    }
  }
}

TEST(Jobs, FewerThanOneJobIsRefused) {
  EXPECT_THROW((void)run_jobs(3, [](std::size_t) {}, {.jobs = 0}), std::invalid_argument);
  EXPECT_GE(default_jobs(), 1);
}

TEST(Jobs, AReplayGetsItsReaderAndWriterThreadsOnlyWithTwoCoresOfItsOwn) {
  // --jobs N is N cores: a pipelined replay keeps about two busy.
  EXPECT_FALSE(replays_pipelined(1, 1));  // one core: one thread
  EXPECT_TRUE(replays_pipelined(2, 1));
  EXPECT_FALSE(replays_pipelined(2, 8));  // two replays at once, one core each
  EXPECT_FALSE(replays_pipelined(3, 2));
  EXPECT_TRUE(replays_pipelined(4, 2));
  EXPECT_TRUE(replays_pipelined(16, 8));
  EXPECT_FALSE(replays_pipelined(15, 8));
  EXPECT_FALSE(replays_pipelined(4, 0));
}

}  // namespace
}  // namespace extwrench
