// The pool of independent runs: every run once, no more at once than asked, and a failing
// run's error passed on after the dealing stops.
#include <gtest/gtest.h>

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
      const RunPoolSummary s = run_pool(count, {parallel}, [&](std::size_t k) {
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

TEST(RunPool, AFailingRunStopsTheDealingAndItsErrorIsPassedOn) {
  std::atomic<int> started{0};
  EXPECT_THROW(run_pool(10, {1},
                        [&](std::size_t k) {
                          ++started;
                          if (k == 2) throw std::runtime_error("run 2 failed");
                        }),
               std::runtime_error);
  EXPECT_EQ(started, 3);  // one at a time: the runs after the failure never start
}

}  // namespace
}  // namespace granmem
