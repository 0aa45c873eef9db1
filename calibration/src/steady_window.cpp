#include "granmem/calibration/steady_window.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// One packing's scatter of `name`'s window means: pooled over the runs of each friction.
double packing_scatter(const std::vector<SteadyState>& means, const std::vector<std::size_t>& cell,
                       const std::string& name) {
  std::map<std::size_t, std::vector<double>> by_cell;
  for (std::size_t k = 0; k < means.size(); ++k) {
    const double v = means[k][name];
    if (std::isfinite(v)) by_cell[cell[k]].push_back(v);
  }
  double squares = 0, dof = 0;
  for (const auto& [c, values] : by_cell) {
    if (values.size() < 2) continue;
    double mean = 0;
    for (double v : values)
      mean += v / double(values.size());
    for (double v : values)
      squares += (v - mean) * (v - mean);
    dof += double(values.size() - 1);
  }
  return dof > 0 ? std::sqrt(squares / dof) : std::nan("");
}

// The twin's mean change of `name` across the window (NaN if no run measured it).
double mean_change(const std::vector<SteadyState>& means, const std::string& name) {
  double sum = 0, n = 0;
  for (const SteadyState& m : means) {
    const double d = m.drift_of(name);
    if (std::isfinite(d)) {
      sum += d;
      ++n;
    }
  }
  return n > 0 ? sum / n : std::nan("");
}

}  // namespace

SteadyWindow choose_steady_window(const std::vector<ObservableSeries>& runs,
                                  const std::vector<std::size_t>& cell,
                                  const std::vector<std::string>& names,
                                  const SteadyWindowOptions& options) {
  if (runs.size() != cell.size()) throw Error("choose_steady_window: one cell per run");
  if (options.last < 1 || options.min_cycles < 2 || options.earliest < 1) {
    throw Error("choose_steady_window: needs a last cycle and windows of 2 cycles or more");
  }
  SteadyWindow chosen;
  for (std::int64_t first = options.earliest; first + options.min_cycles - 1 <= options.last;
       ++first) {
    std::vector<SteadyState> means;
    for (const ObservableSeries& run : runs)
      means.push_back(window_means(run, {first, options.last}));
    chosen.unsteady.clear();
    for (const std::string& name : names) {
      const double change = mean_change(means, name), scatter = packing_scatter(means, cell, name);
      if (!std::isfinite(change) || !std::isfinite(scatter)) continue;
      if (std::abs(change) > scatter) {
        chosen.unsteady = name;
        chosen.change = change;
        chosen.scatter = scatter;
        break;
      }
    }
    if (chosen.unsteady.empty()) {
      chosen.window = {first, options.last};
      chosen.steady = true;
      return chosen;
    }
  }
  chosen.window = {
      std::max<std::int64_t>(options.earliest, options.last - options.fallback_cycles + 1),
      options.last};
  return chosen;
}

}  // namespace granmem
