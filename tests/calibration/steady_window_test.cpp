// The steady-state window chosen from the twin's runs: on series whose transients end at
// known cycles, the window starts where the last of them has ended.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "checks.hpp"
#include "granmem/calibration/steady_window.hpp"

namespace granmem {
namespace {

constexpr double kScatter = 0.01;  // one packing's: seed offsets -1, 0, +1 times this

// 2 frictions x 3 packings. "packing" falls by `step` a cycle until cycle `packing_end`,
// "rotation" until `rotation_end`, then both are flat; each run is offset by its packing.
std::vector<ObservableSeries> twin(std::int64_t last, std::int64_t packing_end,
                                   std::int64_t rotation_end, double step,
                                   std::vector<std::size_t>* cell) {
  std::vector<ObservableSeries> runs;
  for (std::size_t friction = 0; friction < 2; ++friction) {
    for (int packing = -1; packing <= 1; ++packing) {
      ObservableSeries s;
      ObservableSeries::Entry density{"packing", {}, {}, true}, rotation{"rotation", {}, {}, false};
      for (std::int64_t c = 1; c <= last; ++c) {
        const double base = 0.6 + 0.05 * double(friction) + kScatter * packing;
        density.cycle.push_back(c);
        density.value.push_back(base + step * double(std::max<std::int64_t>(0, packing_end - c)));
        rotation.cycle.push_back(c);
        rotation.value.push_back(base + step * double(std::max<std::int64_t>(0, rotation_end - c)));
      }
      s.entries = {density, rotation};
      runs.push_back(s);
      cell->push_back(friction);
    }
  }
  return runs;
}

TEST(SteadyWindow, StartsWhereTheLastTransientHasEnded) {
  std::vector<std::size_t> cell;
  // A step of 10 scatters: a window holding one cycle of a transient changes across it by
  // 6 step (L - 1) / (L (L + 1)) >= 0.3 step for L <= 20 cycles, beyond the scatter.
  const auto runs = twin(20, 5, 8, 10 * kScatter, &cell);
  SteadyWindowOptions o;
  o.last = 20;
  const SteadyWindow w = choose_steady_window(runs, cell, {"packing", "rotation"}, o);
  EXPECT_TRUE(w.steady);
  EXPECT_EQ(w.window, (CycleRange{8, 20}));
  EXPECT_TRUE(w.unsteady.empty());
  // With the rotation left out, the packing's end alone sets it.
  EXPECT_EQ(choose_steady_window(runs, cell, {"packing"}, o).window, (CycleRange{5, 20}));
  // An experiment scanned from cycle 11 on: no window starts before it.
  o.earliest = 11;
  EXPECT_EQ(choose_steady_window(runs, cell, {"packing", "rotation"}, o).window,
            (CycleRange{11, 20}));
}

TEST(SteadyWindow, FallsBackToTheLastCyclesAndNamesWhatStillChanges) {
  std::vector<std::size_t> cell;
  const auto runs = twin(20, 5, 40, 10 * kScatter, &cell);  // the rotation never settles
  SteadyWindowOptions o;
  o.last = 20;
  const SteadyWindow w = choose_steady_window(runs, cell, {"packing", "rotation"}, o);
  EXPECT_FALSE(w.steady);
  EXPECT_EQ(w.window, (CycleRange{11, 20}));
  EXPECT_EQ(w.unsteady, "rotation");
  // Its change across the last window looked at (cycles 18-20): two steps, against the
  // packings' scatter (the offsets -1, 0, +1 times kScatter: a standard deviation of it).
  EXPECT_NEAR(w.change, -2 * 10 * kScatter, 1e-12);
  EXPECT_NEAR(w.scatter, kScatter, 1e-12);
}

TEST(SteadyWindow, RefusesRunsWithoutTheirCells) {
  std::vector<std::size_t> cell;
  auto runs = twin(10, 2, 2, kScatter, &cell);
  cell.pop_back();
  SteadyWindowOptions o;
  o.last = 10;
  EXPECT_NE(testing::error_message([&] {
              choose_steady_window(runs, cell, {"packing"}, o);
            }).find("one cell per run"),
            std::string::npos);
}

}  // namespace
}  // namespace granmem
