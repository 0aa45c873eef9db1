#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"

namespace granmem {

// One twin run: its sliding friction, its packing's seed, and the steady-state values of
// the observables (window means: packing fraction, wall force, mean rotation, ...), in the
// same order as the experiment's; its rolling friction where the fit is joint.
struct ObservableRun {
  double mu_s = 0;
  std::uint64_t seed = 1;
  std::vector<double> values;
  double mu_r = 0;
};

struct ObservableFitOptions {
  // Each observable across the runs as a polynomial of this degree in ln(mu_s).
  int degree = 2;
  // With runs of two seeds or more: each run at an interior friction, taken as the
  // experiment, is fitted with the other seeds' runs; how far ln(fitted / true) falls from
  // zero is how far one packing moves the fit, and the interval takes it when it is the
  // larger error.
  bool cross_validate = true;
  // How those errors carry to the experiment's friction: as the RMS of each error over
  // the error the trend predicts at its friction (the Fisher error of the observables'
  // slope against their scatter), times the predicted error at the fit (true); or as
  // their plain RMS, wherever the runs are (false).
  bool cross_validation_by_friction = true;
  // Each experiment value's standard error beyond one packing's scatter (SteadyState::
  // systematic), in the experiment's order, added to its covariance; empty: none. It is not
  // one packing's error, so the cross-validation across packings does not stand in for it:
  // the interval takes the larger of the fit's packing error and the cross-validated one,
  // and this error's share beside it.
  std::vector<double> experiment_systematic;
};

struct ObservableFit {
  double mu_s = 0;
  std::array<double, 2> mu_s_ci95{0, 0};
  double log_mu_s_sigma = 0;    // standard error of ln(mu_s) that sets the interval
  double chi2 = 0, dof = 0;     // at the fit; dof = observables - 1
  double error_scale = 1;       // sqrt(chi2 / dof) when above 1
  double gls_sigma = 0;         // the GLS fit's own standard error of ln(mu_s), widened on a misfit
  double systematic_sigma = 0;  // the experiment's systematic errors' share of gls_sigma
  double cross_validated_sigma = 0;  // one packing's error in ln(mu_s) at the fit, held out
  std::size_t cross_validations = 0;
  std::vector<double> scatter;     // per observable: the runs' scatter about the trend
  std::vector<double> resolution;  // per observable: its own error in ln(mu_s) at the fit
  std::vector<double> model;       // the observables predicted at the fit
  // The trend through the runs, for figures: curve[o][k] is observable o at curve_mu_s[k],
  // which spans the runs' range evenly in ln(mu_s).
  std::vector<double> curve_mu_s;
  std::vector<std::vector<double>> curve;
  std::vector<std::string> names;  // the observables' names, where the caller gave them
  std::size_t simulations = 0;
  std::string method;
};

// Fits mu_s so that the twin's steady-state observables match the experiment's: each
// observable is a polynomial in ln(mu_s) fitted across the runs; the runs' residuals about
// it give the covariance of one packing's values (realization noise, shrunk towards its
// diagonal as the runs' spare degrees of freedom are few); the experiment, one packing,
// has that covariance, and the trend its leverage's share. Ceres minimizes the generalized
// least squares over ln(mu_s) within the runs' range; the 95 % interval is from its
// covariance (Student's t for the spare runs), widened by sqrt(chi2/dof) on a misfit, or
// from the cross-validation across packings when that error is larger. Throws Error for
// fewer runs than degree + 2, runs of one friction, or values of unequal count.
ObservableFit fit_friction_to_observables(const std::vector<double>& experiment,
                                          const std::vector<ObservableRun>& runs,
                                          const ObservableFitOptions& options = {});

// One twin run's steady state (steady_state() of its window).
struct SteadyStateRun {
  double mu_s = 0;
  std::uint64_t seed = 1;
  SteadyState state;
  double mu_r = 0;
};

// The same fit on the observables that the experiment and every run have, by name, in the
// experiment's order, with the experiment's systematic errors where it has them (a scan has
// no lid height, a run without axes no rotations; the lid's
// packing_fraction is left out where height_packing_fraction, the same from positions, is
// there), or on `only` where it is not empty (Error naming one that is missing). The
// fit's `names` says which were used.
ObservableFit fit_friction_to_steady_state(const SteadyState& experiment,
                                           const std::vector<SteadyStateRun>& runs,
                                           const ObservableFitOptions& options = {},
                                           const std::vector<std::string>& only = {});

// One cycle ahead (docs/CALIBRATION.md, "One cycle ahead"): the twin placed anew from the
// experiment's frame of each cycle before one of the window and driven that one cycle. A
// segment is one such cycle: the experiment's observables over it (with its placed
// read-back as systematic errors) and the twin's runs over it (the same frictions and
// seeds in every segment).
struct SteadyStateSegment {
  SteadyState experiment;
  std::vector<SteadyStateRun> runs;
};

struct SegmentedFit {
  double mu_s = 0;
  std::array<double, 2> mu_s_ci95{0, 0};
  double log_mu_s_sigma = 0;    // the mean's standard error that sets the interval
  double scatter_sigma = 0;     // the segments' fits' standard deviation over sqrt(segments)
  double systematic_sigma = 0;  // the experiment's systematic errors' share, the segments' mean
  std::vector<double> segment_mu_s;       // each segment's own fit
  std::vector<double> segment_log_sigma;  // its GLS standard error in ln mu_s
  std::vector<double> scatter;            // per observable: the runs' scatter about their trends
  // For figures, per observable: every segment's runs less that segment's experiment
  // (offset[o][k] at run_mu_s[k]); the segments' trends less their experiments, averaged
  // (curve_offset[o][k] at curve_mu_s[k]), which crosses 0 near the fit; and the error of
  // that mean at the experiment (the scatter over sqrt(segments), the systematic error).
  std::vector<double> run_mu_s;
  std::vector<std::vector<double>> offset;
  std::vector<double> curve_mu_s;
  std::vector<std::vector<double>> curve_offset;
  std::vector<double> offset_error;
  std::vector<std::string> names;
  std::size_t runs = 0;  // per segment
  std::string method;
};

// Each segment fitted as fit_friction_to_steady_state() fits a window, but against the
// runs' covariance about their trends pooled over the segments (a segment's spare runs are
// few, and one cycle's scatter is alike from cycle to cycle), shrunk towards its diagonal;
// ln mu_s is the mean of the segments' fits, its standard error their scatter over
// sqrt(segments) with the systematic share (common to every segment) in quadrature, the
// 95 % interval with Student's t for segments - 1. The segments' scatter holds every error
// that differs from cycle to cycle (the experiment's one-cycle chaos, the twin's, the
// trend's); one common to every cycle only as far as the systematic errors say it. On the
// observables every segment's experiment and runs have (or `only`). Throws Error for fewer
// than 3 segments, or a segment the fit of a window would refuse.
SegmentedFit fit_friction_by_segments(const std::vector<SteadyStateSegment>& segments,
                                      const ObservableFitOptions& options = {},
                                      const std::vector<std::string>& only = {});

// The joint fit of the sliding and rolling frictions: the same model with each observable
// a polynomial of total degree `degree` in (ln mu_s, ln mu_r) across runs that vary both
// (e.g. a 3 x 3 grid per packing); Ceres fits both logs within the runs' ranges.
struct JointObservableFit {
  double mu_s = 0, mu_r = 0;
  std::array<double, 2> mu_s_ci95{0, 0}, mu_r_ci95{0, 0};  // marginal 95 % intervals
  // The covariance of (ln mu_s, ln mu_r) behind the intervals and the region, row-major.
  std::array<double, 4> log_covariance{0, 0, 0, 0};
  double correlation = 0;
  // The joint 95 % confidence region's boundary, (mu_s, mu_r) points around it: the
  // ellipse of the covariance in the logs at chi-square(2 dof) 95 %, scaled by Student's t
  // for the dof the covariance rests on.
  std::vector<std::array<double, 2>> region95;
  double chi2 = 0, dof = 0;  // dof = observables - 2
  double error_scale = 1;
  std::array<double, 2> gls_sigma{0, 0}, cross_validated_sigma{0, 0};
  std::array<double, 2> systematic_sigma{0, 0};  // the experiment's systematic errors' share
  std::size_t cross_validations = 0;
  std::vector<double> scatter, model;
  std::vector<std::string> names;
  std::size_t simulations = 0;
  std::string method;
};

// Throws Error for fewer runs than the polynomial's terms + 1, runs of one mu_s or one mu_r,
// or fewer observables than 2.
JointObservableFit fit_frictions_to_observables(const std::vector<double>& experiment,
                                                const std::vector<ObservableRun>& runs,
                                                const ObservableFitOptions& options = {});
JointObservableFit fit_frictions_to_steady_state(const SteadyState& experiment,
                                                 const std::vector<SteadyStateRun>& runs,
                                                 const ObservableFitOptions& options = {},
                                                 const std::vector<std::string>& only = {});

}  // namespace granmem
