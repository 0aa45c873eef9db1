#pragma once

#include <vector>

#include "granmem/calibration/power_law_fit.hpp"

namespace granmem {

// The memory signature of a read-out curve, as numbers (the paper's Figs 4, 5, 7).
// A curve: a mean displacement (or rotation) against the read-out amplitude A', with the
// standard errors of the means, amplitudes ascending and positive.
struct ReadoutCurve {
  std::vector<double> amplitude, value, error;
};

// How far the curve at the training amplitude A stands below the power law through its
// two neighbours (interpolated in log-log): depth = 1 - value(A) / interpolated, > 0 for a
// dip. Errors propagated from the three points' standard errors.
struct MemoryDip {
  double value = 0, value_error = 0;
  double interpolated = 0, interpolated_error = 0;
  double depth = 0, depth_error = 0;
};
// Throws Error when A is not in the curve or is its first or last point.
MemoryDip interpolation_dip(const ReadoutCurve& curve, double training_amplitude);

// The trained curve at A over the untrained packing's (the same read-out of the packing
// before any training) at A: < 1 where training made A more reversible.
struct TrainedRatio {
  double ratio = 0, error = 0;
};
TrainedRatio trained_ratio(const ReadoutCurve& trained, const ReadoutCurve& untrained,
                           double training_amplitude);

// Power laws value = a A'^b fitted to the points at and below A, and at and above A
// (the paper's rotations: b ~ 0.7 below, ~ 1.4 above after 400 cycles), with the Ceres
// power-law fit (pure power law, Cauchy loss, errors as weights). A side with fewer than
// four points is left unfitted (converged false, points 0).
struct ReadoutExponents {
  PowerLawFit below, above;
};
ReadoutExponents readout_exponents(const ReadoutCurve& curve, double training_amplitude);

}  // namespace granmem
