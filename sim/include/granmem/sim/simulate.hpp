#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <set>
#include <string>

#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/run_settings.hpp"
#include "granmem/sim/simulate_settings.hpp"

// `granmem simulate` as a library call: deposit grains under a lid (or take a packing from a
// checkpoint) and compress them cyclically, writing the end-of-cycle store and checkpoints.
namespace granmem {

struct SimulateOptions {
  RunSettings settings = default_simulate_settings();  // every option, as text with units
  // The options set explicitly: a resumed run keeps its recorded value of the others, and
  // one started from a trained packing refuses a new value of a packing option.
  std::set<std::string> given;
  std::string resume;      // continue the run of this checkpoint
  std::string start_from;  // a new protocol from the packing in this checkpoint
  int threads = 0;         // OpenMP threads; 0: one per 2,500 grains, up to all cores
  // What the run is doing, a line at a time (deposition, cycling), and its progress.
  std::function<void(const std::string&)> log;
  DepositProgress deposit_progress;
  std::function<void(const CyclicProgress&)> progress;
  // Set (by a signal handler, or Python's KeyboardInterrupt) to stop between two steps with
  // a checkpoint; read from the first cycle on. `cycles_start` is called just before it.
  const std::atomic<bool>* stop = nullptr;
  std::function<void()> cycles_start;
};

struct SimulateSummary {
  RunSettings settings;  // as used (a resumed or started-from run's merged settings)
  std::size_t grains = 0;
  CyclicSummary cycles;
  std::string checkpoint;
  // What the command line prints on success: the rate and the files written.
  std::string Report() const;
};

// Checks every setting and output path before the packing is made (Error naming the
// option), then deposits or reads the packing and runs the cycles. An interrupted run
// returns with cycles.interrupted set, its checkpoint written.
SimulateSummary simulate(const SimulateOptions& options);

}  // namespace granmem
