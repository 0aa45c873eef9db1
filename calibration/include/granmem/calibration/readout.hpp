#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "granmem/calibration/memory_signature.hpp"
#include "granmem/core/table.hpp"
#include "granmem/rotation/grain_motion.hpp"
#include "granmem/sim/readout_sweep.hpp"

namespace granmem {

// The memory read-out of the paper ("Encoding and reading memory"): the sweep of read-out
// runs from trained states (sim/readout_sweep), then the read-out curves: how far the
// grains end each read-out cycle from where the trained state had them.
struct ReadoutOptions {
  ReadoutSweepOptions sweep;
  // All grains by default: a simulation sees every grain, walls included.
  MotionOptions motion;
  std::size_t bootstrap = 200;  // resamples of the grains for each error
  std::uint64_t seed = 1;       // of the bootstrap

  // Throws Error naming what is wrong: the sweep's options (ReadoutSweepOptions::validate),
  // the motion's (MotionOptions::validate).
  void validate() const;
};

// One point of a read-out curve: a state read out at amplitude A', after read-out cycle
// `cycle`. Lengths in grain diameters d; rotational displacements are the angle times d/2.
// Errors are bootstrap standard errors over grains.
struct ReadoutPoint {
  std::size_t state = 0;
  std::int64_t trained_cycles = 0;
  double training_amplitude = 0;  // fraction of the box; NaN if unknown
  double amplitude = 0;           // A', fraction of the box
  std::int64_t cycle = 0;         // read-out cycle, from 1
  std::size_t grains = 0;
  double dr = 0, dr_error = 0;                  // mean |r_c - r_0|
  double msd = 0, msd_error = 0;                // mean |r_c - r_0|^2, d^2
  double rot_single = 0, rot_single_error = 0;  // single-axis (cavity axis), as seen
  double rot_full = 0, rot_full_error = 0;      // full rotation
  double reversibility = 0;                     // mean |r_c - r_(c-1)|: NaN for the first cycle
};

// The memory signature of one state's read-out (its first read-out cycle), as numbers:
// the dip of the displacement (and of the single-axis rotation) at the training amplitude
// below its neighbours, the
// displacement there over the untrained packing's (a state of 0 trained cycles in the same
// sweep; NaN without one), and the power laws of the rotations below and above it.
struct StateSignature {
  std::size_t state = 0;
  std::int64_t trained_cycles = 0;
  double training_amplitude = 0;
  MemoryDip dr_dip, rot_single_dip;
  TrainedRatio dr_untrained{std::nan(""), std::nan("")};
  ReadoutExponents rot_single, rot_full;
};

// The signature of every state whose sweep holds its training amplitude between two others.
std::vector<StateSignature> readout_signatures(const std::vector<ReadoutPoint>& points);
// Columns: state, trained_cycles, training_amplitude_pct, dr_dip, dr_dip_err,
// dr_over_untrained, dr_over_untrained_err, rot_single_dip, rot_single_dip_err, then for
// rot_single and rot_full: _exp_below,
// _exp_below_err, _exp_above, _exp_above_err (NaN where a side has under four points).
Table signature_table(const std::vector<StateSignature>& signatures);

struct ReadoutSummary {
  ReadoutSweepSummary sweep;
  std::vector<ReadoutPoint> points;  // run by run, cycles ascending
  std::vector<StateSignature> signatures;
  double diameter = 0;                    // m, the length unit of the points
  std::filesystem::path table;            // <dir>/readout.csv
  std::filesystem::path signature_table;  // <dir>/memory.csv
};

// The points of one finished read-out run (its end-of-cycle store).
std::vector<ReadoutPoint> readout_points(const ReadoutRun& run, const ReadoutOptions& options);

// The points as a table with stable column names (state, trained_cycles,
// training_amplitude_pct, amplitude_pct, cycle, grains, dr_d, dr_err_d, msd_d2, msd_err_d2,
// rot_single_d, rot_single_err_d, rot_full_d, rot_full_err_d, reversibility_d).
Table readout_table(const std::vector<ReadoutPoint>& points);

// Validates the options, runs (or reuses) the sweep, computes every point and signature and writes
// <dir>/readout.csv and <dir>/memory.csv. In an
// MPI job every rank calls it and shares the runs; rank 0 alone computes the points and
// writes the table (the other ranks return the sweep only).
ReadoutSummary readout(const ReadoutOptions& options,
                       const std::function<void(const ReadoutSweepProgress&)>& progress = {});

}  // namespace granmem
