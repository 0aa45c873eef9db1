#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <vector>

#include "granmem/tracking/grain_fit.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {

// The lab's classical hole axis, the baseline the model fit is measured against (and what
// `locate` gives without the axis fit): the eigenvector of the largest eigenvalue of the
// scatter of the hole's voxels (fluid fraction >= 0.5 in a normalised scan) within
// `within` x the radius of the centre. Physical coordinates with `voxel_size` (anisotropic
// voxels weigh as the space they sample). NaN when fewer than three voxels are bright.
Eigen::Vector3d lab_hole_axis(const Stack& normalized, const Eigen::Vector3d& centre, double radius,
                              const Eigen::Vector3d& voxel_size, double within = 0.8);

// Where the refit starts, from the model fit: its blurs (0: the model fit's, alike in every
// direction) and changes of its radius and levels. locate starts every grain from the
// medians of a sample's refits: nearer, fewer iterations.
struct HoleAxisStart {
  double blur_across = 0, blur_along_z = 0;
  double radius_change = 0, fluid_change = 0, grain_change = 0;
};

struct HoleAxisOptions {
  // Of the radius: the voxels the axis is fitted to (locate: the model fit's radius plus
  // the sample's median shortfall, the refit's).
  double within = 0.8;
  int max_iterations = 30;
  HoleAxisStart start;
};

struct HoleAxisFit {
  Eigen::Vector3d axis = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double sigma = std::numeric_limits<double>::quiet_NaN();  // standard error, radians
  double blur_across = 0, blur_along_z = 0;                 // fitted, as the radius
  double radius = 0, fluid = 1, grain = 0;                  // fitted
  bool converged = false;
};

// The grain fraction of `grain` at p seen through a Gaussian blur of widths `blur_across`
// (x, y) and `blur_along_z` (z), exact to quadrature (the image fit_hole_axis fits; locate
// sees each grain's neighbours so: with a cheaper one, the hole's plug with flat ends, a
// noiseless packing's axes were 0.46 / 1.19 deg (median / p95) against 0.43 / 0.99 at PSF
// 1.0 / 1.0 / 1.5 voxel, 1.5x slices, and locate no faster).
double blurred_grain_fraction(const Eigen::Vector3d& p, const HoledSphere& grain,
                              double blur_across, double blur_along_z);
// The same at each of `points` nearer its centre than `reach`, added to `sum` (one a
// point; the image's set-up, the grain's, made once).
void add_blurred_grain_fraction(const std::vector<Eigen::Vector3d>& points, double reach,
                                const HoledSphere& grain, double blur_across, double blur_along_z,
                                std::vector<double>& sum);

// The hole's axis refitted on the grain's inner voxels (within `within` x its radius of
// the fitted centre; `inner` as GrainWindow, `clear` optional: 1 - the neighbours' summed
// grain fraction there), its centre held, with its radius, the levels and a blur of its
// own across the slices (x, y) and along z. Why: a model blurred alike in every
// direction, fitted to a scan blurred more along z (coarse slices), tilts the axis by
// degrees; so does any profile only near the blurred holed sphere's when the blur along z
// is wide on the grain's scale (a sphere's rim blurred as a plane, the hole's mouths left
// out, a radius held from the model fit, which runs small there: with PSF 1.0 / 1.0 / 1.5
// voxel and 1.5x slices, 0.6-1.2 voxel at d = 12, and a noiseless grain's axis then tilts
// by up to 2 deg away from or towards z). The residuals are those of the image blurred
// exactly (blurred_grain_fraction: Gauss-Legendre over the blur's offset along the axis
// between the mouths, the annulus' cross-section blurred by the covariance across it),
// with its own Jacobian (Jets; ~5 Levenberg-Marquardt iterations): a noiseless grain's
// axis within 0.05 deg of the truth for PSFs 0.5-1.0 voxel across, 0.7-1.5 along z,
// isotropic or 1.5x slices (bench/axis_single.cpp). Starts from `grain` and `options.start`.
HoleAxisFit fit_hole_axis(const GrainWindow& inner, const GrainFit& grain,
                          const HoleAxisOptions& options = {});

}  // namespace granmem
