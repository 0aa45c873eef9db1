#include "granmem/calibration/friction_series.hpp"

#include <omp.h>

#include <atomic>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

#include "granmem/core/error.hpp"

namespace granmem {

Simulation with_sliding_friction(const Simulation& packing, double mu_s, bool walls_follow) {
  PhysicsOptions physics = packing.physics();
  physics.contact.mu_s = mu_s;
  if (walls_follow) physics.wall.mu_s = mu_s;
  Simulation sim(packing.grains(), packing.container(), physics);
  sim.restore(packing.time(), packing.step_count(), packing.pair_histories(),
              packing.wall_histories(), packing.wall_loads());
  return sim;
}

std::filesystem::path friction_run_path(const std::filesystem::path& dir, double mu_s) {
  char name[64];
  std::snprintf(name, sizeof name, "mu_s_%.4g.h5", mu_s);
  return dir / name;
}

std::vector<std::filesystem::path> run_friction_series(
    const Simulation& packing, const std::vector<double>& mu_s,
    const FrictionSeriesOptions& options,
    const std::function<void(std::size_t, const CyclicProgress&)>& progress) {
  if (mu_s.empty()) throw Error("friction series: no mu_s values");
  for (double m : mu_s) {
    if (!(m > 0 && std::isfinite(m))) throw Error("friction series: mu_s must be positive");
  }
  std::vector<std::filesystem::path> out;
  for (double m : mu_s)
    out.push_back(friction_run_path(options.dir, m));
  const int workers =
      std::max(1, std::min<int>(int(mu_s.size()), options.parallel > 0
                                                      ? options.parallel
                                                      : int(std::thread::hardware_concurrency())));
  std::atomic<std::size_t> next{0};
  std::mutex report;
  std::exception_ptr failure;
  auto work = [&] {
    for (std::size_t k; (k = next++) < mu_s.size();) {
      try {
        Simulation sim = with_sliding_friction(packing, mu_s[k], options.walls_follow);
        sim.set_threads(1);  // parallel over runs: one thread each
        CyclicOptions c = options.protocol;
        c.out = out[k];
        c.checkpoint.clear();
        c.parameters["calibrate/mu_s"] = std::to_string(mu_s[k]);
        ProtocolState state;
        run_cycles(sim, c, state, [&](const CyclicProgress& p) {
          if (!progress) return;
          const std::lock_guard<std::mutex> lock(report);
          progress(k, p);
        });
      } catch (...) {
        const std::lock_guard<std::mutex> lock(report);
        if (!failure) failure = std::current_exception();
        next = mu_s.size();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w)
    pool.emplace_back(work);
  work();
  for (std::thread& t : pool)
    t.join();
  if (failure) std::rethrow_exception(failure);
  return out;
}

}  // namespace granmem
