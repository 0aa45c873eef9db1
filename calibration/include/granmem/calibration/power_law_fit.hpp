#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace granmem {

// How a packing relaxes towards its steady state under cyclic driving: the mean
// displacement per cycle m(n) = m_inf + a n^(-b), a power law in the cycle number n on
// top of a steady state (the paper's Fig. 3: b ~ 0.7 for translations, ~ 0.6 for
// rotations).
struct PowerLawOptions {
  // The steady state m_inf: fitted with a and b when 0; else held at the mean of the last
  // this many points (the paper's choice: its last 20 cycles), which are then not fitted.
  std::size_t steady_points = 0;
  // Hold m_inf at 0: a pure power law a n^(-b) (the read-out's rotations against 1/A').
  bool pure = false;
  // Cauchy loss: residuals beyond this many standard errors (in the points' unit when no
  // errors are given) are down-weighted, so that a few cycles with a collective slip do not
  // pull the exponent.
  double loss_scale = 2.0;
};

struct PowerLawFit {
  double steady = 0, steady_sigma = 0;  // m_inf and its standard error
  double amplitude = 0;                 // a
  double exponent = 0, exponent_sigma = 0;
  std::array<double, 2> exponent_ci95{0, 0};
  std::size_t points = 0;   // cycles fitted
  double reduced_chi2 = 0;  // robust cost per degree of freedom
  bool converged = false;
};

// Fits m(n) = m_inf + a n^(-b) to the points (n > 0, finite m) with Ceres (robust Cauchy
// loss, residuals in units of `sigma`: the standard errors of the means; when empty, every
// point weighs the same and the scatter is estimated from the fit). The exponent's interval is from
// Ceres' covariance, scaled by the reduced chi^2 when the scatter exceeds the standard errors.
// Throws Error for fewer than four usable points.
PowerLawFit fit_power_law(const std::vector<double>& n, const std::vector<double>& m,
                          const std::vector<double>& sigma, const PowerLawOptions& options = {});

}  // namespace granmem
