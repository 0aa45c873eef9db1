#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"

namespace granmem {

// One simulated run of a friction series: its sliding friction and its observables.
struct FrictionRun {
  double mu_s = 0;
  CycleObservables observables;
  std::uint64_t seed = 1;  // of the packing: runs of other seeds are other realizations
};

// How the locating error of a scan is put into the simulated displacements before they are
// compared with measured ones: a displacement is the difference of two located positions,
// so each component gets Gaussian noise of sqrt(2) sigma times the axis' share `shape`.
enum class NoiseModel { none, fixed, fitted };

struct FrictionFitOptions {
  // The summaries: the smoothed CDF of log(dr) at the experiment's quantiles of these
  // probabilities.
  std::vector<double> probabilities{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9};
  // Width of the Gaussian kernel smoothing the CDFs, in log(dr): the summaries are then
  // smooth functions of the parameters, as Ceres needs.
  double kernel_width = 0.05;
  // Resamples of whole grains (their cycles are correlated) for the summaries' covariance.
  std::size_t bootstrap = 400;
  NoiseModel noise = NoiseModel::none;
  // Per unit of sigma, the standard deviation of a located position along x, y, z in grain
  // diameters (e.g. the voxel size over the diameter: sigma is then in voxels).
  Eigen::Vector3d noise_shape{1, 1, 1};
  double noise_sigma = 0;          // the value (fixed) or ignored (fitted)
  std::size_t noise_replicas = 4;  // noisy copies of each simulated displacement
  std::uint64_t seed = 1;          // of the bootstrap and the noise: fixed draws
  // Summaries of each cycle's distribution rather than of the window's pooled one: in a
  // transient (the first cycles after deposition) the displacements change from cycle to
  // cycle, and how they change depends on the friction.
  bool per_cycle = false;
  // The simulated summaries across the runs as a polynomial in log(mu_s) of this degree
  // (at most the number of runs - 1).
  int degree = 2;
  // With runs of two seeds or more: each run at an interior friction, taken as the
  // experiment, is fitted with the other seeds' runs; the spread of the fitted ln(mu_s)
  // about the run's own is the realization's part of the error, measured where it matters.
  bool cross_validate = true;
};

struct FrictionFit {
  double mu_s = 0;
  std::array<double, 2> mu_s_ci95{0, 0};
  double log_mu_s_sigma = 0;  // standard error of ln(mu_s), after the scale below
  double noise_sigma = 0, noise_sigma_error = 0;
  double chi2 = 0;         // generalized least squares, at the fit
  double dof = 0;          // summaries - fitted parameters
  double error_scale = 1;  // sqrt(chi2 / dof) when above 1: misfit widens the interval
  // Variance of the runs about the polynomial over their grains' sampling variance (>= 1,
  // traces): the realization noise of a packing, added to the experiment's errors and the
  // runs'.
  double overdispersion = 1;
  // Cross-validation across packings: RMS of ln(fitted / true mu_s) over the held-out runs
  // (0 when not made), and how many.
  double cross_validated_sigma = 0;
  std::size_t cross_validations = 0;
  bool converged = false;
  std::size_t simulations = 0;
  std::vector<double> thresholds;             // dr at the summaries, diameters
  std::vector<std::int64_t> threshold_cycle;  // the cycle of each summary (0: pooled window)
  std::vector<double> experiment_cdf;         // F_exp at the thresholds
  std::vector<double> experiment_error;       // bootstrap standard errors
  std::vector<double> model_cdf;              // simulated F at the fit
  std::vector<std::vector<double>> run_cdf;   // per run (with the fitted noise)
  std::string method;                         // how the interval was obtained, in words
};

// Fits mu_s (and the locating noise, when fitted) so that the simulated end-of-cycle
// displacement distribution matches the experiment's: residuals are the differences of
// the smoothed CDFs of log(dr) at the experiment's quantiles, whitened by their covariance
// (bootstrap over grains, experiment and simulation, plus the runs' own scatter about the
// trend beyond it: the realization noise of a packing); the simulated CDFs are a polynomial in
// log(mu_s) fitted across the runs, so mu_s stays within the runs' range. The 95 %
// interval is from Ceres' covariance, widened by sqrt(chi2/dof) when the misfit exceeds
// the sampling errors. Throws Error for fewer runs than degree + 1 or an empty sample.
FrictionFit fit_friction(const CycleObservables& experiment, const std::vector<FrictionRun>& runs,
                         const FrictionFitOptions& options);

// The simulated dr with the noise model's noise added (one noisy copy of each), diameters:
// what the distances at the best fit compare with the experiment.
std::vector<double> noisy_dr(const CycleObservables& simulated, const Eigen::Vector3d& noise_shape,
                             double sigma, std::uint64_t seed);

}  // namespace granmem
