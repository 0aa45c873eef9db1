#include "granmem/calibration/memory_signature.hpp"

#include <cmath>
#include <string>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// Index of A in the curve (relative tolerance: amplitudes pass through text and back).
std::size_t index_of(const ReadoutCurve& c, double a) {
  for (std::size_t k = 0; k < c.amplitude.size(); ++k) {
    if (std::abs(c.amplitude[k] - a) <= 1e-9 * a) return k;
  }
  throw Error("memory signature: the training amplitude " + std::to_string(a * 100) +
              " % is not among the read-out amplitudes");
}

PowerLawFit fit_side(const ReadoutCurve& c, std::size_t from, std::size_t to) {
  std::vector<double> inverse, value, error;
  for (std::size_t k = from; k <= to; ++k) {
    inverse.push_back(1 / c.amplitude[k]);  // value = a (1/A')^(-b) = a A'^b
    value.push_back(c.value[k]);
    error.push_back(c.error[k]);
  }
  PowerLawOptions o;
  o.pure = true;
  if (inverse.size() < 4) return {};
  try {
    return fit_power_law(inverse, value, error, o);
  } catch (const Error&) {
    return {};  // too few points with a finite error
  }
}

}  // namespace

MemoryDip interpolation_dip(const ReadoutCurve& c, double a) {
  const std::size_t k = index_of(c, a);
  if (k == 0 || k + 1 >= c.amplitude.size()) {
    throw Error(
        "memory signature: the training amplitude needs a read-out amplitude on each "
        "side");
  }
  // log v(A) = (1 - t) log v_lo + t log v_hi, t the position of A between its neighbours.
  const double t =
      std::log(a / c.amplitude[k - 1]) / std::log(c.amplitude[k + 1] / c.amplitude[k - 1]);
  const double lo = c.value[k - 1], hi = c.value[k + 1];
  MemoryDip d;
  d.value = c.value[k];
  d.value_error = c.error[k];
  d.interpolated = std::exp((1 - t) * std::log(lo) + t * std::log(hi));
  const double rel_lo = c.error[k - 1] / lo, rel_hi = c.error[k + 1] / hi;
  const double rel_interp = std::hypot((1 - t) * rel_lo, t * rel_hi);
  d.interpolated_error = d.interpolated * rel_interp;
  const double ratio = d.value / d.interpolated;
  d.depth = 1 - ratio;
  d.depth_error = ratio * std::hypot(d.value_error / d.value, rel_interp);
  return d;
}

TrainedRatio trained_ratio(const ReadoutCurve& trained, const ReadoutCurve& untrained, double a) {
  const std::size_t i = index_of(trained, a), j = index_of(untrained, a);
  TrainedRatio r;
  r.ratio = trained.value[i] / untrained.value[j];
  r.error = r.ratio * std::hypot(trained.error[i] / trained.value[i],
                                 untrained.error[j] / untrained.value[j]);
  return r;
}

ReadoutExponents readout_exponents(const ReadoutCurve& c, double a) {
  const std::size_t k = index_of(c, a);
  return {fit_side(c, 0, k), fit_side(c, k, c.amplitude.size() - 1)};
}

}  // namespace granmem
