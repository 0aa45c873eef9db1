#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"

namespace granmem {

// Where the twin has become steady: the steady-state fit's window chosen from the runs
// themselves (calibrate --window auto) instead of assumed.
struct SteadyWindowOptions {
  std::int64_t last = 0;        // the window's last cycle (the experiment's last)
  std::int64_t earliest = 1;    // the first cycle a window may start at (the experiment's)
  std::int64_t min_cycles = 3;  // the shortest window looked at
  // Without a steady window: the last this many cycles, as the paper's 10 after 500.
  std::int64_t fallback_cycles = 10;
};

struct SteadyWindow {
  CycleRange window{0, 0};
  bool steady = false;  // false: no window was steady; `window` is the fallback
  // The observable that kept the last window looked at from being steady ("" if steady),
  // its mean change across that window and one packing's scatter.
  std::string unsteady;
  double change = 0, scatter = 0;
};

// The longest window [c, last] over which every named observable's mean change across the
// window, averaged over the twin's runs, is within one packing's scatter: the standard
// deviation of the runs' window means among the runs of one friction (`cell`: each run's
// friction, or friction pair, as an index; at least two runs in some cell). The
// least-squares change (window_means' drift) is compared, the criterion of calibrate's
// "not yet a steady state" note.
SteadyWindow choose_steady_window(const std::vector<ObservableSeries>& runs,
                                  const std::vector<std::size_t>& cell,
                                  const std::vector<std::string>& names,
                                  const SteadyWindowOptions& options);

}  // namespace granmem
