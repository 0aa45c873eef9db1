#include "granmem/calibration/power_law_fit.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// (m_n - m_inf - a n^-b) / sigma_n, with a = exp(log_a) to keep it positive.
struct RelaxationResidual {
  double n, m, sigma;
  template <class T>
  bool operator()(const T* steady, const T* log_a, const T* b, T* r) const {
    r[0] = (T(m) - steady[0] - exp(log_a[0] - b[0] * T(std::log(n)))) / T(sigma);
    return true;
  }
};

}  // namespace

PowerLawFit fit_power_law(const std::vector<double>& n, const std::vector<double>& m,
                          const std::vector<double>& sigma, const PowerLawOptions& options) {
  if (n.size() != m.size() || (!sigma.empty() && sigma.size() != n.size())) {
    throw Error("power-law fit: cycles, means and errors differ in length");
  }
  std::vector<std::size_t> use;
  for (std::size_t k = 0; k < n.size(); ++k) {
    const bool weighted = sigma.empty() || (std::isfinite(sigma[k]) && sigma[k] > 0);
    if (n[k] > 0 && std::isfinite(m[k]) && weighted) use.push_back(k);
  }
  PowerLawFit fit;
  double steady = 0;
  const bool held = options.steady_points > 0 || options.pure;
  if (options.steady_points > 0 && !options.pure) {
    if (use.size() < options.steady_points + 4) {
      throw Error("power-law fit: " + std::to_string(use.size()) + " cycles, need " +
                  std::to_string(options.steady_points + 4) + " with a steady state of the last " +
                  std::to_string(options.steady_points));
    }
    for (std::size_t k = use.size() - options.steady_points; k < use.size(); ++k)
      steady += m[use[k]];
    steady /= double(options.steady_points);
    use.resize(use.size() - options.steady_points);
  }
  if (use.size() < 4) {
    throw Error("power-law fit: " + std::to_string(use.size()) + " usable cycles, need 4");
  }

  // Start: steady state just under the smallest mean, a from the first point, b = 0.7.
  double lowest = m[use[0]];
  for (std::size_t k : use)
    lowest = std::min(lowest, m[k]);
  if (!held) steady = lowest - 0.1 * std::abs(lowest);
  double b = 0.7;
  double log_a = std::log(std::max(m[use[0]] - steady, 1e-30)) + b * std::log(n[use[0]]);

  ceres::Problem problem;
  for (std::size_t k : use) {
    const double s = sigma.empty() ? 1.0 : sigma[k];
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RelaxationResidual, 1, 1, 1, 1>(
                                 new RelaxationResidual{n[k], m[k], s}),
                             new ceres::CauchyLoss(options.loss_scale), &steady, &log_a, &b);
  }
  if (held) problem.SetParameterBlockConstant(&steady);
  problem.SetParameterLowerBound(&b, 0, 0.0);
  problem.SetParameterUpperBound(&b, 0, 10.0);
  ceres::Solver::Options solver;
  solver.max_num_iterations = 200;
  solver.function_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  fit.steady = steady;
  fit.amplitude = std::exp(log_a);
  fit.exponent = b;
  fit.points = use.size();
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  const double dof = double(use.size()) - (held ? 2.0 : 3.0);
  fit.reduced_chi2 = 2 * summary.final_cost / dof;
  // With errors given, the covariance is absolute; scatter beyond them (or no errors at
  // all) scales it by the reduced chi^2.
  const double scale = sigma.empty() ? fit.reduced_chi2 : std::max(1.0, fit.reduced_chi2);

  ceres::Covariance::Options co;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> blocks{{&b, &b}};
  if (!held) blocks.push_back({&steady, &steady});
  const double nan = std::nan("");
  fit.exponent_sigma = fit.steady_sigma = nan;
  if (covariance.Compute(blocks, &problem)) {
    double var_b = 0;
    covariance.GetCovarianceBlock(&b, &b, &var_b);
    fit.exponent_sigma = std::sqrt(var_b * scale);
    if (!held) {
      double var_s = 0;
      covariance.GetCovarianceBlock(&steady, &steady, &var_s);
      fit.steady_sigma = std::sqrt(var_s * scale);
    } else {
      fit.steady_sigma = 0;
    }
  }
  fit.exponent_ci95 = {b - 1.96 * fit.exponent_sigma, b + 1.96 * fit.exponent_sigma};
  return fit;
}

}  // namespace granmem
