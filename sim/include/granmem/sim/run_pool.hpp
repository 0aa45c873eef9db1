#pragma once

#include <cstddef>
#include <functional>

namespace granmem {

// Many independent runs side by side, one thread each: the amplitudes of a memory
// read-out, the frictions and packings of a calibration's simulated twin. A run is a
// whole simulation, so the runs, not the grains, are what is shared out.
struct RunPoolOptions {
  int parallel = 0;  // runs at once; 0: one per core
};

struct RunPoolSummary {
  std::size_t runs = 0;  // runs done
  int workers = 0;       // threads that ran them
};

// Calls run(k) for every k in [0, count), `parallel` at a time, each on a thread of its own
// (a run sets its simulation to one thread). Runs are dealt in the order of k as workers
// free up. The first exception thrown by a run stops the dealing; the runs under way are
// finished, and the exception is rethrown.
RunPoolSummary run_pool(std::size_t count, const RunPoolOptions& options,
                        const std::function<void(std::size_t)>& run);

}  // namespace granmem
