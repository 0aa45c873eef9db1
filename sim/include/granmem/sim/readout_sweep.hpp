#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "granmem/sim/quasi_static.hpp"
#include "granmem/sim/run_pool.hpp"
#include "granmem/sim/wall_drive.hpp"

namespace granmem {

// The paper's read-out of a trained packing's memory: from one trained state, one run per
// read-out amplitude A', each `cycles` cycles 0 -> A' -> 0 (or the symmetric drive), all
// starting from the same state. A run's end-of-cycle store holds the trained state as
// frame 0, then the end of each read-out cycle.
struct ReadoutSweepOptions {
  std::vector<std::filesystem::path> states;  // checkpoints written between cycles
  std::vector<double> amplitudes;             // A' as fractions of the box along y; 0 allowed
  std::int64_t cycles = 1;                    // read-out cycles per amplitude
  DriveSymmetry symmetry = DriveSymmetry::asymmetric;
  DriveShape shape = DriveShape::cosine;
  // The wall's peak speed is the quasi-static speed of this inertial number under the
  // state's lid (docs/QUASISTATIC.md), so the period grows with A'. A' = 0 keeps the wall
  // still for the period of the smallest positive amplitude.
  double inertial_number = kQuasiStaticInertialNumber;
  // Each state's own training amplitude (its `amplitude` setting) is added to its sweep.
  bool include_training_amplitude = true;
  std::filesystem::path dir;  // the runs' stores (readout_run_path), made if missing
  RunPoolOptions pool;

  // Throws Error naming what is wrong before any state is read: no amplitudes, a negative
  // one or one of half the box or more, every one 0, no read-out cycle, an inertial number
  // that is not positive, no state, no output folder.
  void validate() const;
};

struct ReadoutRun {
  std::size_t state = 0;                     // index into ReadoutSweepOptions::states
  std::int64_t trained_cycles = 0;           // cycles the state had run
  double training_amplitude = std::nan("");  // fraction of the box; NaN if unknown
  double amplitude = 0;                      // fraction of the box
  std::filesystem::path store;
  bool reused = false;  // a finished run of the same settings found in dir
};

struct ReadoutSweepProgress {
  std::size_t done = 0, runs = 0;  // runs finished (reused ones included), of
  double seconds_left = 0;
};

struct ReadoutSweepSummary {
  std::vector<ReadoutRun> runs;  // state-major, amplitudes ascending
  double wall_seconds = 0;
};

// Validates the options and checks every state before running anything (Error naming the
// bad one: a file that is not a checkpoint, a state in the middle of a cycle, states of
// other boxes or grains), then runs
// the sweep on the pool. Runs whose store exists with the same state, amplitude and
// cycles are reused, not run again. `progress` is called as runs finish.
ReadoutSweepSummary run_readout_sweep(
    const ReadoutSweepOptions& options,
    const std::function<void(const ReadoutSweepProgress&)>& progress = {});

// Read-out amplitudes as fractions of the box: a comma list of percentages
// ("0%,0.5%,1%") or a log-spaced range "lo%:hi%:count" (the paper's "0.05%:2.5%:12").
std::vector<double> parse_amplitude_sweep(const std::string& text);

// <dir>/readout_<state stem>_A<amplitude in percent>.h5
std::filesystem::path readout_run_path(const std::filesystem::path& dir,
                                       const std::filesystem::path& state, double amplitude);

}  // namespace granmem
