#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <vector>

#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/simulation.hpp"

namespace granmem {

// The simulated twin of an experiment run at several sliding frictions: the same deposited
// packing (positions, contact springs) and the same protocol for each, so that only the
// friction differs between the runs.
struct FrictionSeriesOptions {
  CyclicOptions protocol;     // drive and cycles (its out and checkpoint are not used)
  std::filesystem::path dir;  // run k goes to dir/mu_s_<value>.h5
  bool walls_follow = true;   // the walls' and lid's sliding friction is the grains'
  int parallel = 0;           // runs at once, one thread each; 0: all cores
};

// The packing with another sliding friction between grains (and on the walls with
// `walls_follow`), every contact's history kept.
Simulation with_sliding_friction(const Simulation& packing, double mu_s, bool walls_follow);

// Runs the protocol from `packing` for each mu_s, independent runs in parallel; returns
// the end-of-cycle stores written, in the order of `mu_s`. `progress(k, p)` is called
// (from the run's thread, one call at a time) as run k completes cycles.
std::vector<std::filesystem::path> run_friction_series(
    const Simulation& packing, const std::vector<double>& mu_s,
    const FrictionSeriesOptions& options,
    const std::function<void(std::size_t, const CyclicProgress&)>& progress = {});

std::filesystem::path friction_run_path(const std::filesystem::path& dir, double mu_s);

}  // namespace granmem
