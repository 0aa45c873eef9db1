#include "granmem/sim/run_pool.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace granmem {

RunPoolSummary run_pool(std::size_t count, const RunPoolOptions& options,
                        const std::function<void(std::size_t)>& run) {
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  const int workers = int(
      std::min<std::size_t>(count, std::size_t(options.parallel > 0 ? options.parallel : cores)));
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex failed;
  std::exception_ptr failure;
  auto work = [&] {
    for (std::size_t k; (k = next++) < count;) {
      try {
        run(k);
        ++done;
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failed);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w)
    pool.emplace_back(work);
  if (workers > 0) work();
  for (std::thread& t : pool)
    t.join();
  if (failure) std::rethrow_exception(failure);
  return {done.load(), workers};
}

}  // namespace granmem
