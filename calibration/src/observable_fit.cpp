#include "granmem/calibration/observable_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "ceres_variance.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

// The observables across the runs: a polynomial in x = ln(mu_s) - centre per observable,
// and the covariance of one run's values about it.
struct Trend {
  double centre = 0;
  int degree = 2;
  Eigen::MatrixXd coefficients;    // (degree + 1) x observables
  Eigen::MatrixXd normal_inverse;  // (X^T X)^-1
  Eigen::MatrixXd covariance;      // observables x observables
  Eigen::VectorXd scatter;         // its diagonal's square roots, before shrinking
  double spare = 0;                // runs - coefficients

  Eigen::RowVectorXd powers(double x) const {
    Eigen::RowVectorXd p(degree + 1);
    for (int k = 0; k <= degree; ++k)
      p(k) = std::pow(x, k);
    return p;
  }
  Eigen::VectorXd predict(double log_mu) const {
    return (powers(log_mu - centre) * coefficients).transpose();
  }
  Eigen::VectorXd slope(double log_mu) const {
    Eigen::RowVectorXd d = Eigen::RowVectorXd::Zero(degree + 1);
    for (int k = 1; k <= degree; ++k)
      d(k) = k * std::pow(log_mu - centre, k - 1);
    return (d * coefficients).transpose();
  }
  // Variance of the trend's prediction over one run's.
  double leverage(double log_mu) const {
    const Eigen::RowVectorXd p = powers(log_mu - centre);
    return (p * normal_inverse * p.transpose())(0, 0);
  }
};

Trend fit_trend(const std::vector<ObservableRun>& runs, int degree) {
  Trend t;
  t.degree = degree;
  const Eigen::Index k = Eigen::Index(runs.size()), m = Eigen::Index(runs.front().values.size());
  for (const ObservableRun& r : runs)
    t.centre += std::log(r.mu_s) / double(k);
  Eigen::MatrixXd x(k, degree + 1), y(k, m);
  for (Eigen::Index i = 0; i < k; ++i) {
    x.row(i) = t.powers(std::log(runs[std::size_t(i)].mu_s) - t.centre);
    y.row(i) = Eigen::Map<const Eigen::RowVectorXd>(runs[std::size_t(i)].values.data(), m);
  }
  t.normal_inverse = (x.transpose() * x).inverse();
  t.coefficients = t.normal_inverse * x.transpose() * y;
  t.spare = double(k - (degree + 1));
  const Eigen::MatrixXd residual = y - x * t.coefficients;
  const Eigen::MatrixXd sample = residual.transpose() * residual / t.spare;
  t.scatter = sample.diagonal().cwiseSqrt();
  // Few spare runs estimate m variances well enough but m(m-1)/2 correlations poorly: the
  // fewer the runs, the more the estimate is shrunk towards its diagonal.
  const double shrink = double(m) / (double(m) + t.spare);
  t.covariance = (1 - shrink) * sample;
  t.covariance.diagonal() = sample.diagonal();
  t.covariance.diagonal().array() += 1e-12 * sample.diagonal().maxCoeff() + 1e-300;
  return t;
}

struct Misfit {
  const Trend* trend;
  Eigen::VectorXd target;
  Eigen::MatrixXd whitening;
  bool operator()(double const* const* p, double* r) const {
    Eigen::Map<Eigen::VectorXd>(r, target.size()) = whitening * (trend->predict(p[0][0]) - target);
    return true;
  }
};

// C = (1 + leverage) Sigma at ln(mu_s): the experiment's realization and the trend's error.
Eigen::MatrixXd whitening_at(const Trend& t, double log_mu) {
  const Eigen::MatrixXd c = (1 + t.leverage(log_mu)) * t.covariance;
  return c.llt().matrixL().solve(Eigen::MatrixXd::Identity(c.rows(), c.cols()));
}

struct OneFit {
  double log_mu = 0, sigma = 0, chi2 = 0;
  Trend trend;
};

OneFit fit_once(const Eigen::VectorXd& target, const std::vector<ObservableRun>& runs, int degree) {
  OneFit f;
  f.trend = fit_trend(runs, degree);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ObservableRun& r : runs) {
    lo = std::min(lo, std::log(r.mu_s));
    hi = std::max(hi, std::log(r.mu_s));
  }
  // Start from the best of a grid: the misfit need not be convex across the range.
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 48; ++k) {
    const double x = lo + (hi - lo) * k / 48.0;
    const double c = (whitening_at(f.trend, x) * (f.trend.predict(x) - target)).squaredNorm();
    if (c < best) {
      best = c;
      f.log_mu = x;
    }
  }
  // Two rounds: the whitening depends on ln(mu_s) through the trend's leverage.
  for (int round = 0; round < 2; ++round) {
    ceres::Problem problem;
    auto* cost = new ceres::DynamicNumericDiffCostFunction<Misfit, ceres::CENTRAL>(
        new Misfit{&f.trend, target, whitening_at(f.trend, f.log_mu)});
    cost->AddParameterBlock(1);
    cost->SetNumResiduals(int(target.size()));
    problem.AddResidualBlock(cost, nullptr, &f.log_mu);
    problem.SetParameterLowerBound(&f.log_mu, 0, lo);
    problem.SetParameterUpperBound(&f.log_mu, 0, hi);
    ceres::Solver::Options so;
    so.max_num_iterations = 100;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    f.chi2 = 2 * summary.final_cost;
    if (round == 1) {
      f.sigma = std::sqrt(parameter_variances(problem, {&f.log_mu})[0]);
    }
  }
  return f;
}

void check_runs(const std::vector<double>& experiment, const std::vector<ObservableRun>& runs,
                int degree) {
  if (degree < 1) throw Error("observable fit: the polynomial degree must be at least 1");
  if (experiment.empty()) throw Error("observable fit: no observable");
  if (runs.size() < std::size_t(degree) + 2) {
    throw Error("observable fit: " + std::to_string(runs.size()) + " runs, need at least " +
                std::to_string(degree + 2) + " (a polynomial of degree " + std::to_string(degree) +
                " in ln mu_s and one spare run for the scatter)");
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ObservableRun& r : runs) {
    if (!(r.mu_s > 0)) throw Error("observable fit: mu_s must be positive");
    if (r.values.size() != experiment.size()) {
      throw Error("observable fit: a run has " + std::to_string(r.values.size()) +
                  " observables, the experiment " + std::to_string(experiment.size()));
    }
    for (double v : r.values)
      if (!std::isfinite(v)) throw Error("observable fit: a run's observable is not finite");
    lo = std::min(lo, r.mu_s);
    hi = std::max(hi, r.mu_s);
  }
  for (double v : experiment)
    if (!std::isfinite(v)) throw Error("observable fit: an experiment's observable is not finite");
  if (!(hi > lo)) throw Error("observable fit: the runs must differ in mu_s");
}

constexpr int kCurvePoints = 60;

bool by_friction(const ObservableRun& a, const ObservableRun& b) {
  return a.mu_s < b.mu_s;
}

}  // namespace

ObservableFit fit_friction_to_observables(const std::vector<double>& experiment,
                                          const std::vector<ObservableRun>& runs,
                                          const ObservableFitOptions& options) {
  check_runs(experiment, runs, options.degree);
  const Eigen::VectorXd target =
      Eigen::Map<const Eigen::VectorXd>(experiment.data(), Eigen::Index(experiment.size()));
  const OneFit f = fit_once(target, runs, options.degree);
  ObservableFit fit;
  fit.mu_s = std::exp(f.log_mu);
  fit.chi2 = f.chi2;
  fit.dof = double(experiment.size()) - 1;
  fit.error_scale = fit.dof > 0 ? std::max(1.0, std::sqrt(fit.chi2 / fit.dof)) : 1.0;
  fit.gls_sigma = f.sigma * fit.error_scale;
  fit.log_mu_s_sigma = fit.gls_sigma;
  double t = student_t_975(f.trend.spare);
  fit.simulations = runs.size();
  const Eigen::VectorXd model = f.trend.predict(f.log_mu), slope = f.trend.slope(f.log_mu);
  const double inflation = std::sqrt(1 + f.trend.leverage(f.log_mu));
  for (Eigen::Index o = 0; o < target.size(); ++o) {
    fit.model.push_back(model(o));
    fit.scatter.push_back(f.trend.scatter(o));
    fit.resolution.push_back(inflation * f.trend.scatter(o) / std::abs(slope(o)));
  }
  fit.curve.resize(std::size_t(target.size()));
  const auto [lo, hi] = std::minmax_element(runs.begin(), runs.end(), by_friction);
  for (int k = 0; k <= kCurvePoints; ++k) {
    const double x = std::log(lo->mu_s) + std::log(hi->mu_s / lo->mu_s) * k / kCurvePoints;
    fit.curve_mu_s.push_back(std::exp(x));
    const Eigen::VectorXd y = f.trend.predict(x);
    for (Eigen::Index o = 0; o < target.size(); ++o)
      fit.curve[std::size_t(o)].push_back(y(o));
  }

  // Cross-validation across packings: a run of known friction fitted with the other
  // seeds' runs, at interior frictions (at the range's ends the bounded fit cannot err
  // outwards).
  if (options.cross_validate) {
    double sum2 = 0;
    for (const ObservableRun& held_out : runs) {
      std::vector<ObservableRun> others;
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const ObservableRun& r : runs) {
        if (r.seed == held_out.seed) continue;
        others.push_back(r);
        lo = std::min(lo, r.mu_s);
        hi = std::max(hi, r.mu_s);
      }
      if (others.size() < std::size_t(options.degree) + 2 ||
          !(lo < held_out.mu_s && held_out.mu_s < hi)) {
        continue;
      }
      const Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(
          held_out.values.data(), Eigen::Index(held_out.values.size()));
      sum2 += std::pow(fit_once(v, others, options.degree).log_mu - std::log(held_out.mu_s), 2);
      ++fit.cross_validations;
    }
    if (fit.cross_validations > 0) {
      fit.cross_validated_sigma = std::sqrt(sum2 / double(fit.cross_validations));
      if (fit.cross_validated_sigma > fit.log_mu_s_sigma) {
        fit.log_mu_s_sigma = fit.cross_validated_sigma;
        t = student_t_975(double(fit.cross_validations));
      }
    }
  }
  fit.mu_s_ci95 = {std::exp(f.log_mu - t * fit.log_mu_s_sigma),
                   std::exp(f.log_mu + t * fit.log_mu_s_sigma)};
  fit.method = "Ceres generalized least squares of " + std::to_string(experiment.size()) +
               " steady-state observables against their trend in ln mu_s (degree " +
               std::to_string(options.degree) + ") across " + std::to_string(runs.size()) +
               " runs, covariance from the runs' scatter about it (" +
               std::to_string(int(f.trend.spare)) + " spare runs, shrunk to its diagonal)" +
               (fit.cross_validations > 0 ? "; cross-validated across packings on " +
                                                std::to_string(fit.cross_validations) + " runs"
                                          : std::string());
  return fit;
}

ObservableFit fit_friction_to_steady_state(const SteadyState& experiment,
                                           const std::vector<SteadyStateRun>& runs,
                                           const ObservableFitOptions& options,
                                           const std::vector<std::string>& only) {
  std::vector<std::string> names;
  for (const std::string& name : only.empty() ? experiment.names : only) {
    const bool everywhere = std::isfinite(experiment[name]) &&
                            std::all_of(runs.begin(), runs.end(), [&](const SteadyStateRun& r) {
                              return std::isfinite(r.state[name]);
                            });
    if (everywhere) {
      names.push_back(name);
    } else if (!only.empty()) {
      throw Error("observable fit: '" + name + "' is not measured in the experiment and every run");
    }
  }
  if (names.empty()) throw Error("observable fit: no observable in the experiment and every run");
  std::vector<double> measured;
  for (const std::string& name : names)
    measured.push_back(experiment[name]);
  std::vector<ObservableRun> twin;
  for (const SteadyStateRun& r : runs) {
    ObservableRun run{r.mu_s, r.seed, {}};
    for (const std::string& name : names)
      run.values.push_back(r.state[name]);
    twin.push_back(std::move(run));
  }
  ObservableFit fit = fit_friction_to_observables(measured, twin, options);
  fit.names = names;
  return fit;
}

}  // namespace granmem
