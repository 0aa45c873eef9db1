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
      options.cores > 0
          ? options.cores
          : std::max(1, int(std::thread::hardware_concurrency()) / std::max(1, ranks.on_node));
  const int workers = int(std::min<std::size_t>(
      mine.size(), std::size_t(options.parallel > 0 ? options.parallel : cores)));
  // A pool asked for fewer runs at once than the machine has cores uses no more cores.
  const int pool_cores = options.parallel > 0 ? std::min(options.parallel, cores) : cores;
  const int share = std::max(1, pool_cores / std::max(1, workers));
  std::size_t next = 0;
  std::atomic<std::size_t> done{0};
  std::mutex failed, dealing;
  std::exception_ptr failure;
  int cores_in_use = 0;
  // The next run and its cores: the last run dealt also takes the cores no run holds (the
  // last of a series, or a single run, need not leave cores unused); no run is dealt after
  // it, so none is left short.
  auto deal = [&](std::size_t& t, int& run_cores) {
    const std::lock_guard<std::mutex> lock(dealing);
    if (next >= mine.size()) return false;
    t = next++;
    run_cores = next == mine.size() ? std::max(share, pool_cores - cores_in_use) : share;
    cores_in_use += run_cores;
    return true;
  };
  auto stopped = [&] { return options.stop && options.stop->load(); };
  auto work = [&] {
    std::size_t t = 0;
    for (int run_cores = 0; !stopped() && deal(t, run_cores);) {
      try {
        run(mine[t], run_cores);
        ++done;
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failed);
        if (!failure) failure = std::current_exception();
        const std::lock_guard<std::mutex> no_more(dealing);
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
