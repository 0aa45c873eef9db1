#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/simulation.hpp"

// granmem's cyclic protocol run by LAMMPS (`simulate --engine lammps`): the packing granmem
// prepared, the contact law mapped as bench/lammps/README.md derives and checks it, the lid
// as a moving frictional plane and the driven wall as another (sim/lammps/*.lmp), under
// mpirun for several ranks; LAMMPS's end-of-cycle dump and per-cycle lines turned into
// granmem's trajectory store. How a lab takes the protocol to a cluster.
namespace granmem {

struct LammpsEngineOptions {
  std::filesystem::path folder;  // the run's LAMMPS files: scripts, data, log, dump, restarts
  int ranks = 1;                 // MPI ranks; 1 runs lmp without mpirun
  std::string lmp = "lmp";       // the LAMMPS executable (GRANULAR and DIPOLE packages)
  std::string mpirun = "mpirun";
  // Go on from the newest restart in `folder` (one is written every checkpoint_every
  // cycles and at the end) instead of starting from the packing (which it does when there
  // is none yet).
  bool resume = false;

  void validate() const;
};

// Refuses, before any work, what LAMMPS cannot run as granmem does: grains of several
// sizes (the contact law maps for one size), no lid, frames at full compression or inside
// cycles, kept states.
void check_lammps_protocol(const CyclicOptions& options, bool one_grain_size, bool lid);

// The run's LAMMPS folder beside its store: <out stem>.lammps
std::filesystem::path lammps_folder(const std::filesystem::path& out);

// The scripts of sim/lammps/, by file name, as built into the library.
const std::vector<std::pair<std::string, std::string>>& lammps_scripts();

// The newest restart in `folder` and the cycles done when it was written; {"", 0} if none.
std::pair<std::filesystem::path, std::int64_t> newest_lammps_restart(
    const std::filesystem::path& folder);

// Runs `options.cycles` cycles of the packing `packing` (equal grains under a lid) on LAMMPS
// (its state before the first cycle) and writes the end-of-cycle store `options.out`: every grain's
// position and cavity axis (no full orientation: LAMMPS carries one body axis, as the experiment
// sees it) and the observables run_cycles writes (wall_force, wall_force_full_compression,
// lid_height, packing_fraction, kinetic_energy, contacts_per_grain). Error for what LAMMPS cannot
// run (check_lammps_protocol) before it starts, and with LAMMPS's own error line when it
// fails. Setting
// `stop` ends LAMMPS (its newest restart is where --resume goes on) and returns with
// `interrupted` set.
CyclicSummary run_cycles_on_lammps(const Simulation& packing, const CyclicOptions& options,
                                   const LammpsEngineOptions& engine,
                                   const std::function<void(const CyclicProgress&)>& progress = {},
                                   const std::atomic<bool>* stop = nullptr);

}  // namespace granmem
