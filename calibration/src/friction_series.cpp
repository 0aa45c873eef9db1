#include "granmem/calibration/friction_series.hpp"

#include <cstdio>
#include <mutex>

#include "granmem/core/error.hpp"
#include "granmem/sim/run_pool.hpp"

namespace granmem {

PhysicsOptions with_frictions(PhysicsOptions physics, const FrictionRunSpec& run,
                              bool walls_follow) {
  physics.contact.mu_s = run.mu_s;
  if (walls_follow) physics.wall.mu_s = run.mu_s;
  if (run.mu_r >= 0) {
    physics.contact.mu_r = run.mu_r;
    if (walls_follow) physics.wall.mu_r = run.mu_r;
  }
  return physics;
}

Simulation with_frictions(const Simulation& packing, const FrictionRunSpec& run,
                          bool walls_follow) {
  Simulation sim(packing.grains(), packing.container(),
                 with_frictions(packing.physics(), run, walls_follow));
  sim.restore(packing.time(), packing.step_count(), packing.pair_histories(),
              packing.wall_histories(), packing.wall_loads());
  return sim;
}

Simulation deposit_at_friction(DepositOptions deposit, const PhysicsOptions& physics,
                               const FrictionRunSpec& run, bool walls_follow, int cores) {
  deposit.seed = run.seed;
  deposit.threads = Simulation::threads_on_own_cores(std::size_t(deposit.grains), cores);
  return granmem::deposit(deposit, with_frictions(physics, run, walls_follow));
}

std::filesystem::path friction_run_path(const std::filesystem::path& dir,
                                        const FrictionRunSpec& run) {
  char name[128];
  if (run.mu_r >= 0) {
    std::snprintf(name, sizeof name, "mu_s_%.4g_mu_r_%.4g_seed_%llu.h5", run.mu_s, run.mu_r,
                  static_cast<unsigned long long>(run.seed));
  } else {
    std::snprintf(name, sizeof name, "mu_s_%.4g_seed_%llu.h5", run.mu_s,
                  static_cast<unsigned long long>(run.seed));
  }
  return dir / name;
}

std::vector<std::filesystem::path> run_friction_series(
    const std::vector<FrictionRunSpec>& runs, const FrictionSeriesOptions& options,
    const std::function<Simulation(const FrictionRunSpec&, int)>& start,
    const std::function<void(std::size_t, const CyclicProgress&)>& progress) {
  if (runs.empty()) throw Error("friction series: no mu_s values");
  for (const FrictionRunSpec& r : runs) {
    if (!(r.mu_s > 0 && std::isfinite(r.mu_s))) {
      throw Error("friction series: mu_s must be positive");
    }
  }
  std::vector<std::filesystem::path> out;
  for (const FrictionRunSpec& r : runs)
    out.push_back(friction_run_path(options.dir, r));
  std::mutex report;
  RunPoolOptions pool;
  pool.parallel = options.parallel;
  pool.stop = options.stop;
  run_pool(runs.size(), pool, [&](std::size_t k, int cores) {
    Simulation sim = start(runs[k], cores);
    sim.set_threads(Simulation::threads_on_own_cores(sim.grains().size(), cores));
    CyclicOptions c = options.protocol;
    c.out = out[k];
    c.checkpoint.clear();
    c.parameters["calibrate/mu_s"] = std::to_string(runs[k].mu_s);
    c.parameters["calibrate/seed"] = std::to_string(runs[k].seed);
    if (runs[k].mu_r >= 0) c.parameters["calibrate/mu_r"] = std::to_string(runs[k].mu_r);
    ProtocolState state;
    const CyclicSummary done = run_cycles(
        sim, c, state,
        [&](const CyclicProgress& p) {
          if (!progress) return;
          const std::lock_guard<std::mutex> lock(report);
          progress(k, p);
        },
        options.stop);
    if (done.interrupted) {  // unfinished: the next call runs it again
      throw Error("stopped during the run at mu_s " + std::to_string(runs[k].mu_s) + ", seed " +
                  std::to_string(runs[k].seed) + " (finished runs are reused when run again)");
    }
  });
  return out;
}

}  // namespace granmem
