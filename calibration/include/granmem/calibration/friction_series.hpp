#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/simulation.hpp"

namespace granmem {

// One run of the simulated twin: its sliding friction and the seed of its packing (runs of
// one seed pour the same grains; other seeds are other realizations of the packing), and
// its rolling friction where the twin varies it (< 0: the physics' own).
struct FrictionRunSpec {
  double mu_s = 0;
  std::uint64_t seed = 1;
  double mu_r = -1;
};

// The simulated twin of an experiment run at several sliding frictions and seeds, under the
// same protocol, so that only the friction (and, between seeds, the realization) differs.
struct FrictionSeriesOptions {
  CyclicOptions protocol;     // drive and cycles (its out and checkpoint are not used)
  std::filesystem::path dir;  // run k goes to friction_run_path(dir, mu_s, seed)
  bool walls_follow = true;   // the walls' and lid's frictions are the grains'
  int parallel = 0;           // runs at once; 0: one per core (run_pool)
  // Set (Python's KeyboardInterrupt): no further run starts, those under way finish, and
  // run_friction_series throws an Error saying how many were done.
  const std::atomic<bool>* stop = nullptr;
};

// The physics with the run's sliding (and rolling, where it sets one) friction between
// grains, and on the walls with `walls_follow`.
PhysicsOptions with_frictions(PhysicsOptions physics, const FrictionRunSpec& run,
                              bool walls_follow);

// The packing with the run's frictions, every contact's history kept.
Simulation with_frictions(const Simulation& packing, const FrictionRunSpec& run, bool walls_follow);

// The grains of `run.seed` poured and deposited at the run's friction: the experiment's
// packing was prepared with its own friction, which sets how loose it is. `cores`: those
// the deposit may use (run_pool's).
Simulation deposit_at_friction(DepositOptions deposit, const PhysicsOptions& physics,
                               const FrictionRunSpec& run, bool walls_follow, int cores = 1);

// Runs the protocol for each spec from the packing `start(spec, cores)` (called in the
// run's thread; `cores`: those the run may use, run_pool's), independent runs in parallel; returns
// the end-of-cycle stores written, in the order of `runs`. `progress(k, p)` is called (from the
// run's thread, one call at a time) as run k completes cycles.
std::vector<std::filesystem::path> run_friction_series(
    const std::vector<FrictionRunSpec>& runs, const FrictionSeriesOptions& options,
    const std::function<Simulation(const FrictionRunSpec&, int)>& start,
    const std::function<void(std::size_t, const CyclicProgress&)>& progress = {});

std::filesystem::path friction_run_path(const std::filesystem::path& dir,
                                        const FrictionRunSpec& run);

}  // namespace granmem
