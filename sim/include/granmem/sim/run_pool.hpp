#pragma once

#include <atomic>
#include <cstddef>
#include <functional>

namespace granmem {

// Many independent runs side by side, each on cores of its own: the amplitudes of a memory
// read-out, the frictions and packings of a calibration's simulated twin. A run is a
// whole simulation, so the runs, not the grains, are what is shared out.
struct RunPoolOptions {
  int parallel = 0;  // runs at once in this process; 0: one per core (shared by the ranks
                     // of an MPI job on the same machine)
  int cores = 0;     // the cores the pool may use; 0: the machine's (shared likewise)
  // Set (Python's KeyboardInterrupt): no further run is started, those under way finish,
  // and run_pool throws an Error saying how many were done.
  const std::atomic<bool>* stop = nullptr;
};

struct RunPoolSummary {
  std::size_t runs = 0;  // runs done by this process
  int workers = 0;       // threads that ran them
  int ranks = 1;         // processes of the MPI job that shared the runs
};

// Calls run(k, cores) for every k in [0, count), `parallel` at a time, each on a thread of
// its own; `cores`: those the run may use, the pool's (the machine's, or `parallel` where
// fewer) shared among the workers, and the last run dealt also those no run holds (the
// last of a series, or a single run, need not leave cores unused). Runs are dealt in the
// order of k as workers free up. The first exception thrown by a run stops the dealing; the runs
// under way are finished, and the exception is rethrown.
//
// In an MPI job (ranks.hpp) every rank calls run_pool with the same runs; rank r does runs
// r, r + size, ... and all return together once every run is done, so that rank 0 may then
// read what every run wrote (to a shared file system). A run that fails on one rank makes
// run_pool throw on every rank. A run's result does not depend on where it ran.
RunPoolSummary run_pool(std::size_t count, const RunPoolOptions& options,
                        const std::function<void(std::size_t, int)>& run);

}  // namespace granmem
