#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "granmem/core/trajectories.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/simulation.hpp"
#include "granmem/sim/wall_drive.hpp"

namespace granmem {

// Cyclic compression by the driven wall, with the outputs the analysis reads.
struct CyclicOptions {
  WallDrive drive;
  std::int64_t cycles = 1;
  // The cycle the packing stands after when the run starts, its first frame's number: 0 for
  // a prepared packing; N for one placed where an experiment's frame of cycle N has its
  // grains, so that the run's cycles are numbered as the experiment's (N+1 to `cycles`).
  std::int64_t first_cycle = 0;
  std::filesystem::path out;  // end-of-cycle trajectory store
  // Also a store of frames at full compression: <out stem>_full_compression.h5.
  bool full_compression_frames = false;
  // In-cycle samples of these grains (ids), `samples_per_cycle` per cycle:
  // <out stem>_in_cycle.h5.
  std::vector<std::int64_t> tracked_grains;
  std::int64_t samples_per_cycle = 0;
  std::filesystem::path checkpoint;               // where checkpoints go; empty: none
  std::int64_t checkpoint_every = 0;              // cycles between checkpoints; 0: at the end only
  std::map<std::string, std::string> parameters;  // written into the outputs' /parameters
  // Cycles after which the full state is kept, as a checkpoint at
  // kept_state_path(out, cycle): the trained states that a memory read-out starts from
  // (0: the packing before the first cycle, the untrained reference).
  std::vector<std::int64_t> keep_states;

  // Throws Error for settings no run can use in a box of this depth along y with this step
  // (a negative amplitude or one of half the box or more, no cycles, a period under four
  // steps). Amplitude 0 keeps the wall still for a period.
  void validate(double box_y, double dt) const;
};

struct CyclicProgress {
  std::int64_t cycle = 0, cycles = 0;  // cycles completed, of
  double particle_steps_per_second = 0;
  double seconds_left = 0;
};

struct CyclicSummary {
  std::int64_t cycles_done = 0;
  bool interrupted = false;  // stopped by `stop`; a checkpoint was written
  double wall_seconds = 0;
  double particle_steps_per_second = 0;
  std::vector<std::filesystem::path> written;
};

std::filesystem::path full_compression_path(const std::filesystem::path& out);
std::filesystem::path in_cycle_path(const std::filesystem::path& out);
// True when `out` holds a finished run of these settings: every one of `parameters` in its
// /parameters with the same value, and end-of-cycle frames up to cycle `cycles`; false
// when there is no such file. Lets a sweep of runs (a calibration twin, a read-out) that
// stopped go on without running its finished runs again. Error for a file it cannot read.
bool finished_run(const std::filesystem::path& out,
                  const std::map<std::string, std::string>& parameters, std::int64_t cycles);

// The header of a store of these grains (indices) of `sim`: ids, radii, the box up to the
// packing's top, positions in m and time in s, axes and orientations.
RunHeader cyclic_run_header(const Simulation& sim, const std::vector<std::size_t>& grains,
                            const char* sample,
                            const std::map<std::string, std::string>& parameters);

// <out stem>_state_cycle<cycle>.h5
std::filesystem::path kept_state_path(const std::filesystem::path& out, std::int64_t cycle);

// Runs the cycles from `state` (a fresh ProtocolState starts at cycle first_cycle + 1 and
// writes the state before it as frame first_cycle; one read from a checkpoint continues where it
// stopped, appending to the outputs). End-of-cycle frames hold every grain's position, orientation
// and cavity axis; per-cycle observables: wall_force and wall_force_full_compression (N,
// the packing's push on the driven wall), lid_height (m), packing_fraction,
// kinetic_energy (J), contacts_per_grain. Checks `stop` every step: when set, it writes
// a checkpoint and returns. Kept states are written with the outputs published up to
// their cycle, so that --resume from one also continues the run exactly.
CyclicSummary run_cycles(Simulation& sim, const CyclicOptions& options, ProtocolState& state,
                         const std::function<void(const CyclicProgress&)>& progress = {},
                         const std::atomic<bool>* stop = nullptr);

}  // namespace granmem
