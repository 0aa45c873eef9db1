#include "granmem/sim/run_pool.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/sim/ranks.hpp"

namespace granmem {

RunPoolSummary run_pool(std::size_t count, const RunPoolOptions& options,
                        const std::function<void(std::size_t, int)>& run) {
  const Ranks ranks = mpi_ranks();
  mpi_barrier();  // every rank has planned the same runs before any run writes
  std::vector<std::size_t> mine;
  for (std::size_t k = std::size_t(ranks.rank); k < count; k += std::size_t(ranks.size))
    mine.push_back(k);
  const int cores =
      std::max(1, int(std::thread::hardware_concurrency()) / std::max(1, ranks.on_node));
  const int workers = int(std::min<std::size_t>(
      mine.size(), std::size_t(options.parallel > 0 ? options.parallel : cores)));
  const int share = std::max(1, cores / std::max(1, workers));
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex failed, dealing;
  std::exception_ptr failure;
  int cores_in_use = 0;
  // The last runs dealt take the cores of the workers left with nothing to do.
  auto deal = [&](std::size_t t) {
    const std::lock_guard<std::mutex> lock(dealing);
    const bool tail = mine.size() - t < std::size_t(workers);
    const int run_cores = tail ? std::max(share, cores - cores_in_use) : share;
    cores_in_use += run_cores;
    return run_cores;
  };
  auto stopped = [&] { return options.stop && options.stop->load(); };
  auto work = [&] {
    for (std::size_t t; !stopped() && (t = next++) < mine.size();) {
      const int run_cores = deal(t);
      try {
        run(mine[t], run_cores);
        ++done;
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failed);
        if (!failure) failure = std::current_exception();
        next = mine.size();
      }
      const std::lock_guard<std::mutex> lock(dealing);
      cores_in_use -= run_cores;
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w)
    pool.emplace_back(work);
  if (workers > 0) work();
  for (std::thread& t : pool)
    t.join();
  const bool any_failed = mpi_any(failure != nullptr);  // every rank waits for every run
  if (failure) std::rethrow_exception(failure);
  if (any_failed) throw Error("run pool: a run failed on another rank (its error is in its log)");
  if (done < mine.size() && stopped()) {
    throw Error("stopped after " + std::to_string(done.load()) + " of " +
                std::to_string(mine.size()) + " runs (finished runs are reused when run again)");
  }
  return {done.load(), workers, ranks.size};
}

}  // namespace granmem
