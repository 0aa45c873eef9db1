// The pool of independent runs: every run once, no more at once than asked, and a failing
// run's error passed on after the dealing stops.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "granmem/sim/run_pool.hpp"

namespace granmem {
namespace {

TEST(RunPool, RunsEveryRunOnceAndNoMoreAtOnceThanAsked) {
  for (int parallel : {1, 2, 3}) {
    for (std::size_t count : {0, 1, 7}) {
      std::vector<std::atomic<int>> calls(count);
      std::atomic<int> running{0}, most{0};
      const RunPoolSummary s = run_pool(count, {parallel}, [&](std::size_t k, int) {
        const int now = ++running;
        for (int m = most; now > m && !most.compare_exchange_weak(m, now);) {
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ++calls[k];
        --running;
      });
      EXPECT_EQ(s.runs, count);
      EXPECT_EQ(s.workers, int(std::min<std::size_t>(count, parallel)));
      for (std::size_t k = 0; k < count; ++k)
        EXPECT_EQ(calls[k], 1) << "run " << k << " of " << count << ", " << parallel << " at once";
      EXPECT_LE(most, parallel);
    }
  }
}

// The cores given to the runs under way never add up to more than the pool's (the
// machine's, or as many as runs at once where fewer); a run alone gets them all, and the
// last run dealt those the others leave.
TEST(RunPool, TheRunsUnderWayShareTheCoresAndARunAloneGetsThemAll) {
  const int machine = std::max(1, int(std::thread::hardware_concurrency()));
  run_pool(1, {}, [&](std::size_t, int cores) { EXPECT_EQ(cores, machine); });
  run_pool(1, {1}, [&](std::size_t, int cores) { EXPECT_EQ(cores, 1); });
  for (int cores : {2, 16}) {
    for (int parallel : {0, 1, 3, 4}) {
      for (std::size_t count : {1, 2, 3, 4, 9}) {
        const int pool = parallel > 0 ? std::min(parallel, cores) : cores;
        std::atomic<int> in_use{0}, most{0};
        run_pool(count, {parallel, cores}, [&](std::size_t k, int given) {
          EXPECT_GE(given, 1);
          const int now = in_use += given;
          for (int m = most; now > m && !most.compare_exchange_weak(m, now);) {
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(2 + 3 * int(k % 3)));
          in_use -= given;
        });
        EXPECT_LE(most, std::max(pool, std::min(int(count), parallel > 0 ? parallel : cores)))
            << count << " runs, " << parallel << " at once, " << cores << " cores";
        if (count == 1) {
          EXPECT_EQ(most, pool);
        }
      }
    }
  }
}

TEST(RunPool, AFailingRunStopsTheDealingAndItsErrorIsPassedOn) {
  std::atomic<int> started{0};
  EXPECT_THROW(run_pool(10, {1},
                        [&](std::size_t k, int) {
                          ++started;
                          if (k == 2) throw std::runtime_error("run 2 failed");
                        }),
               std::runtime_error);
  EXPECT_EQ(started, 3);  // one at a time: the runs after the failure never start
}

}  // namespace
}  // namespace granmem
