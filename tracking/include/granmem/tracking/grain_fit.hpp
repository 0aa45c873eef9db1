#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "granmem/tracking/holed_sphere.hpp"

namespace granmem {

// The voxels around one grain: physical positions, normalised intensities (fluid 1,
// grain 0) and, optionally, how much of each the neighbouring grains leave clear, 1 where
// no neighbour reaches: prod (1 - M_neighbour), or, `additive`, 1 - sum M_neighbour, their
// blurred grain fractions added to the grain's own (the blur is linear and the grains do
// not overlap: the scan's image; the product leaves the blurred rims that touching grains
// share too bright, which tilted the axis refit's axes and pulled the model fits' centres
// towards their neighbours). The axis refit (fit_hole_axis) always adds.
struct GrainWindow {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> intensity;
  std::vector<double> clear;  // empty: neighbours not modelled
  bool additive = false;      // for fit_grain: clear is 1 - sum M_neighbour
};

// A blurred holed sphere fitted to a window by least squares (Ceres' TinySolver,
// Levenberg-Marquardt, analytic Jacobian): centre, radius, the blurs across the slices and
// along z, fluid and grain levels,
// and the hole's axis when the grain has a hole. The scan is modelled as
//   b - (b - g) (1 - (1 - M) clear)
// so that neighbours seen in the window are part of the model instead of pulling the fit.
struct GrainFit {
  HoledSphere sphere;
  double fluid = 1, grain = 0;  // b, g
  double rms = 0;               // residual root mean square
  int iterations = 0;
  bool converged = false;
  // The fitted axis' standard error, radians (from the cost's curvature); NaN when the axis
  // was not fitted or the fit did not converge.
  double axis_sigma = std::numeric_limits<double>::quiet_NaN();
  // The centre's standard error along x, y, z (the covariance's diagonal), in the window's
  // length; NaN when the fit did not converge.
  Eigen::Vector3d centre_sigma =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

struct GrainFitOptions {
  bool fit_axis = true;         // with a hole: also the axis
  bool standard_errors = true;  // centre_sigma and axis_sigma (a fit that only starts another: no)
  // The blurs across and along z, the radius and the levels are correlated where the blur
  // is wide: at 40, fits of 9-pixel grains under a blur along z of 0.4 R stopped short,
  // and 1-3 % of the grains were lost.
  int max_iterations = 80;
};

// Starts from `start` (its centre, radius, blurs, axis and hole fraction).
GrainFit fit_grain(const GrainWindow& window, const HoledSphere& start,
                   const GrainFitOptions& options = {});

}  // namespace granmem
