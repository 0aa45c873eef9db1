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

// The fitted log frictions: (ln mu_s) or (ln mu_s, ln mu_r).
using LogFriction = Eigen::VectorXd;

LogFriction log_friction(const ObservableRun& run, int dims) {
  LogFriction x(dims);
  x(0) = std::log(run.mu_s);
  if (dims == 2) x(1) = std::log(run.mu_r);
  return x;
}

// The exponents of a polynomial of total degree `degree` in `dims` variables.
std::vector<std::array<int, 2>> polynomial_terms(int dims, int degree) {
  std::vector<std::array<int, 2>> terms;
  for (int total = 0; total <= degree; ++total)
    for (int a = total; a >= 0; --a)
      if (dims == 2 || a == total) terms.push_back({a, total - a});
  return terms;
}

// The observables across the runs: a polynomial in x = log frictions - centre per
// observable, and the covariance of one run's values about it.
struct Trend {
  LogFriction centre;
  std::vector<std::array<int, 2>> terms;
  Eigen::MatrixXd coefficients;    // terms x observables
  Eigen::MatrixXd normal_inverse;  // (X^T X)^-1
  Eigen::MatrixXd covariance;      // observables x observables
  Eigen::MatrixXd sample;          // the runs' covariance about the trend, before shrinking
  Eigen::VectorXd scatter;         // its diagonal's square roots
  double spare = 0;                // runs - terms

  Eigen::RowVectorXd powers(const LogFriction& x) const {
    Eigen::RowVectorXd p(Eigen::Index(terms.size()));
    for (std::size_t t = 0; t < terms.size(); ++t) {
      p(Eigen::Index(t)) = 1;
      for (Eigen::Index d = 0; d < x.size(); ++d)
        p(Eigen::Index(t)) *= std::pow(x(d) - centre(d), terms[t][std::size_t(d)]);
    }
    return p;
  }
  Eigen::VectorXd predict(const LogFriction& x) const {
    return (powers(x) * coefficients).transpose();
  }
  // d(prediction) / d(log frictions): observables x dims.
  Eigen::MatrixXd gradient(const LogFriction& x) const {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(Eigen::Index(terms.size()), x.size());
    for (std::size_t t = 0; t < terms.size(); ++t) {
      for (Eigen::Index k = 0; k < x.size(); ++k) {
        const int e = terms[t][std::size_t(k)];
        if (e == 0) continue;
        double v = e * std::pow(x(k) - centre(k), e - 1);
        for (Eigen::Index j = 0; j < x.size(); ++j)
          if (j != k) v *= std::pow(x(j) - centre(j), terms[t][std::size_t(j)]);
        d(Eigen::Index(t), k) = v;
      }
    }
    return coefficients.transpose() * d;
  }
  // Variance of the trend's prediction over one run's.
  double leverage(const LogFriction& x) const {
    const Eigen::RowVectorXd p = powers(x);
    return (p * normal_inverse * p.transpose())(0, 0);
  }
};

// Few spare runs estimate m variances well enough but m(m-1)/2 correlations poorly: the
// fewer the runs, the more the estimate is shrunk towards its diagonal.
Eigen::MatrixXd shrunk_covariance(const Eigen::MatrixXd& sample, double spare) {
  const double m = double(sample.rows());
  const double shrink = m / (m + spare);
  Eigen::MatrixXd c = (1 - shrink) * sample;
  c.diagonal() = sample.diagonal();
  c.diagonal().array() += 1e-12 * sample.diagonal().maxCoeff() + 1e-300;
  return c;
}

Trend fit_trend(const std::vector<ObservableRun>& runs, int dims, int degree) {
  Trend t;
  t.terms = polynomial_terms(dims, degree);
  const Eigen::Index k = Eigen::Index(runs.size()), m = Eigen::Index(runs.front().values.size());
  t.centre = LogFriction::Zero(dims);
  for (const ObservableRun& r : runs)
    t.centre += log_friction(r, dims) / double(k);
  Eigen::MatrixXd x(k, Eigen::Index(t.terms.size())), y(k, m);
  for (Eigen::Index i = 0; i < k; ++i) {
    x.row(i) = t.powers(log_friction(runs[std::size_t(i)], dims));
    y.row(i) = Eigen::Map<const Eigen::RowVectorXd>(runs[std::size_t(i)].values.data(), m);
  }
  t.normal_inverse = (x.transpose() * x).inverse();
  t.coefficients = t.normal_inverse * x.transpose() * y;
  t.spare = double(k) - double(t.terms.size());
  const Eigen::MatrixXd residual = y - x * t.coefficients;
  t.sample = residual.transpose() * residual / t.spare;
  t.scatter = t.sample.diagonal().cwiseSqrt();
  t.covariance = shrunk_covariance(t.sample, t.spare);
  return t;
}

// The experiment's observables and each one's systematic variance (zero for a held-out run).
struct Target {
  Eigen::VectorXd value, systematic;
};

struct Misfit {
  const Trend* trend;
  Eigen::VectorXd target;
  Eigen::MatrixXd whitening;
  int dims;
  bool operator()(double const* const* p, double* r) const {
    LogFriction x(dims);
    for (int d = 0; d < dims; ++d)
      x(d) = p[d][0];
    Eigen::Map<Eigen::VectorXd>(r, target.size()) = whitening * (trend->predict(x) - target);
    return true;
  }
};

// C = (1 + leverage) Sigma + S at x: the experiment's realization, the trend's error and
// the experiment's systematic variances S.
Eigen::MatrixXd whitening_at(const Trend& t, const LogFriction& x,
                             const Eigen::VectorXd& systematic) {
  Eigen::MatrixXd c = (1 + t.leverage(x)) * t.covariance;
  c.diagonal() += systematic;
  return c.llt().matrixL().solve(Eigen::MatrixXd::Identity(c.rows(), c.cols()));
}

// The variance of each log friction a fit at x would have: the diagonal of the inverse
// Fisher matrix of the trend's gradient against the realization and trend errors there;
// infinite where the observables do not move with a friction there.
Eigen::VectorXd predicted_variance(const Trend& t, const LogFriction& x) {
  const Eigen::Index m = t.covariance.rows();
  const Eigen::MatrixXd w = whitening_at(t, x, Eigen::VectorXd::Zero(m)) * t.gradient(x);
  const Eigen::FullPivLU<Eigen::MatrixXd> fisher(w.transpose() * w);
  if (!fisher.isInvertible()) {
    return Eigen::VectorXd::Constant(x.size(), std::numeric_limits<double>::infinity());
  }
  return fisher.inverse().diagonal();
}

// The experiment's systematic variances' share of a fit's covariance at x: with the GLS
// weights A = (G^T C^-1 G)^-1 G^T C^-1 its covariance A C A^T splits into the packing's
// A (1 + leverage) Sigma A^T and the systematic's A S A^T.
Eigen::MatrixXd systematic_share(const Trend& t, const LogFriction& x,
                                 const Eigen::VectorXd& systematic) {
  const Eigen::MatrixXd none = Eigen::MatrixXd::Zero(x.size(), x.size());
  if (systematic.isZero()) return none;
  const Eigen::MatrixXd w = whitening_at(t, x, systematic);
  const Eigen::MatrixXd wg = w * t.gradient(x);
  const Eigen::FullPivLU<Eigen::MatrixXd> fisher(wg.transpose() * wg);
  if (!fisher.isInvertible()) return none;
  const Eigen::MatrixXd a = fisher.inverse() * wg.transpose() * w;
  return a * systematic.asDiagonal() * a.transpose();
}

struct OneFit {
  LogFriction x;
  Eigen::MatrixXd covariance;  // of x, from Ceres
  double chi2 = 0;
  Trend trend;
};

std::pair<LogFriction, LogFriction> bounds(const std::vector<ObservableRun>& runs, int dims) {
  LogFriction lo = LogFriction::Constant(dims, std::numeric_limits<double>::infinity());
  LogFriction hi = -lo;
  for (const ObservableRun& r : runs) {
    lo = lo.cwiseMin(log_friction(r, dims));
    hi = hi.cwiseMax(log_friction(r, dims));
  }
  return {lo, hi};
}

// The GLS fit against a trend already through the runs.
OneFit fit_to_trend(const Target& target, const std::vector<ObservableRun>& runs, int dims,
                    Trend trend) {
  OneFit f;
  f.trend = std::move(trend);
  const auto [lo, hi] = bounds(runs, dims);
  // Start from the best of a grid: the misfit need not be convex across the range.
  const int n = dims == 1 ? 48 : 16;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= (dims == 2 ? n : 0); ++j) {
      LogFriction x = lo + (hi - lo) * (double(i) / n);
      if (dims == 2) x(1) = lo(1) + (hi(1) - lo(1)) * j / n;
      const double c =
          (whitening_at(f.trend, x, target.systematic) * (f.trend.predict(x) - target.value))
              .squaredNorm();
      if (c < best) {
        best = c;
        f.x = x;
      }
    }
  }
  // Two rounds: the whitening depends on the frictions through the trend's leverage.
  std::vector<double> p(f.x.data(), f.x.data() + dims);
  for (int round = 0; round < 2; ++round) {
    ceres::Problem problem;
    auto* cost = new ceres::DynamicNumericDiffCostFunction<Misfit, ceres::CENTRAL>(
        new Misfit{&f.trend, target.value, whitening_at(f.trend, f.x, target.systematic), dims});
    std::vector<double*> blocks;
    for (int d = 0; d < dims; ++d) {
      cost->AddParameterBlock(1);
      blocks.push_back(&p[std::size_t(d)]);
    }
    cost->SetNumResiduals(int(target.value.size()));
    problem.AddResidualBlock(cost, nullptr, blocks);
    for (int d = 0; d < dims; ++d) {
      problem.SetParameterLowerBound(blocks[std::size_t(d)], 0, lo(d));
      problem.SetParameterUpperBound(blocks[std::size_t(d)], 0, hi(d));
    }
    ceres::Solver::Options so;
    so.max_num_iterations = 100;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    f.chi2 = 2 * summary.final_cost;
    f.x = Eigen::Map<const LogFriction>(p.data(), dims);
    if (round == 1) f.covariance = parameter_covariance(problem, blocks);
  }
  return f;
}

OneFit fit_once(const Target& target, const std::vector<ObservableRun>& runs, int dims,
                int degree) {
  return fit_to_trend(target, runs, dims, fit_trend(runs, dims, degree));
}

void check_runs(const std::vector<double>& experiment, const std::vector<ObservableRun>& runs,
                int dims, const ObservableFitOptions& options) {
  const int degree = options.degree;
  if (degree < 1) throw Error("observable fit: the polynomial degree must be at least 1");
  const std::vector<double>& systematic = options.experiment_systematic;
  if (!systematic.empty() && systematic.size() != experiment.size()) {
    throw Error("observable fit: " + std::to_string(systematic.size()) + " systematic errors for " +
                std::to_string(experiment.size()) + " observables");
  }
  for (double e : systematic)
    if (!(e >= 0) || !std::isfinite(e))
      throw Error("observable fit: a systematic error must be finite and not negative");
  if (experiment.size() < std::size_t(dims)) {
    throw Error("observable fit: " + std::to_string(experiment.size()) + " observables for " +
                std::to_string(dims) + " frictions");
  }
  const std::size_t terms = polynomial_terms(dims, degree).size();
  if (runs.size() < terms + 1) {
    throw Error("observable fit: " + std::to_string(runs.size()) + " runs, need at least " +
                std::to_string(terms + 1) + " (a polynomial of degree " + std::to_string(degree) +
                " in the log frictions and one spare run for the scatter)");
  }
  for (const ObservableRun& r : runs) {
    if (!(r.mu_s > 0) || (dims == 2 && !(r.mu_r > 0))) {
      throw Error("observable fit: the frictions must be positive");
    }
    if (r.values.size() != experiment.size()) {
      throw Error("observable fit: a run has " + std::to_string(r.values.size()) +
                  " observables, the experiment " + std::to_string(experiment.size()));
    }
    for (double v : r.values)
      if (!std::isfinite(v)) throw Error("observable fit: a run's observable is not finite");
  }
  for (double v : experiment)
    if (!std::isfinite(v)) throw Error("observable fit: an experiment's observable is not finite");
  const auto [lo, hi] = bounds(runs, dims);
  if (!(hi(0) > lo(0))) throw Error("observable fit: the runs must differ in mu_s");
  if (dims == 2 && !(hi(1) > lo(1))) throw Error("observable fit: the runs must differ in mu_r");
}

// Cross-validation across packings: a run of known frictions fitted with the other seeds'
// runs, at interior frictions (at the range's ends the bounded fit cannot err outwards).
// One packing moves the fit by what its observables' scatter is against their slope, which
// changes with friction (in ln mu_s ~2x more at 0.1 than at 0.35 on the structure), so
// each error is also measured against the error the whole twin's trend predicts at its
// friction. Not the held-out fit's own trend: it rests on fewer spare runs (with two
// packings, on one packing's), and its covariance misses the packings' offsets that the
// held-out errors are there to measure; the whole trend gives the error's shape across
// friction, the held-out errors its scale.
struct CrossValidation {
  LogFriction rms;    // RMS error of each log friction, wherever the runs are
  LogFriction ratio;  // RMS of each error over the predicted one
  std::size_t count = 0;
};
CrossValidation cross_validate(const std::vector<ObservableRun>& runs, const Trend& whole, int dims,
                               int degree) {
  LogFriction error2 = LogFriction::Zero(dims), ratio2 = LogFriction::Zero(dims);
  std::size_t count = 0;
  for (const ObservableRun& held_out : runs) {
    std::vector<ObservableRun> others;
    for (const ObservableRun& r : runs)
      if (r.seed != held_out.seed) others.push_back(r);
    if (others.size() < polynomial_terms(dims, degree).size() + 1) continue;
    const auto [lo, hi] = bounds(others, dims);
    const LogFriction truth = log_friction(held_out, dims);
    if (((truth - lo).array() <= 0).any() || ((hi - truth).array() <= 0).any()) continue;
    const Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(
        held_out.values.data(), Eigen::Index(held_out.values.size()));
    const Eigen::VectorXd predicted = predicted_variance(whole, truth);
    if (!predicted.allFinite()) continue;  // no slope there: no scale to measure it by
    const Target exact{v, Eigen::VectorXd::Zero(v.size())};
    const LogFriction e2 = (fit_once(exact, others, dims, degree).x - truth).cwiseAbs2();
    error2 += e2;
    ratio2 += e2.cwiseQuotient(predicted);
    ++count;
  }
  if (count == 0) return {LogFriction::Zero(dims), LogFriction::Zero(dims), 0};
  return {(error2 / double(count)).cwiseSqrt(), (ratio2 / double(count)).cwiseSqrt(), count};
}

// The cross-validated error of each log friction at x (the plain RMS where the trend has
// no slope at x to carry the ratio by).
LogFriction cross_validated_sigma(const CrossValidation& cv, const Trend& trend,
                                  const LogFriction& x, const ObservableFitOptions& options) {
  if (!options.cross_validation_by_friction) return cv.rms;
  const Eigen::VectorXd predicted = predicted_variance(trend, x);
  if (!predicted.allFinite()) return cv.rms;
  return cv.ratio.cwiseProduct(predicted.cwiseSqrt());
}

constexpr int kCurvePoints = 60;

bool by_friction(const ObservableRun& a, const ObservableRun& b) {
  return a.mu_s < b.mu_s;
}

// The trend across the runs' frictions for figures, each observable less `less`, added
// `weight` times into mu_s / curve (sized on the first call).
void add_curve(const Trend& trend, const std::vector<ObservableRun>& runs,
               const Eigen::VectorXd& less, double weight, std::vector<double>& mu_s,
               std::vector<std::vector<double>>& curve) {
  const auto [lo, hi] = std::minmax_element(runs.begin(), runs.end(), by_friction);
  const bool first = mu_s.empty();
  if (first) {
    mu_s.resize(kCurvePoints + 1);
    curve.assign(std::size_t(less.size()), std::vector<double>(kCurvePoints + 1, 0.0));
  }
  for (int k = 0; k <= kCurvePoints; ++k) {
    LogFriction x(1);
    x(0) = std::log(lo->mu_s) + std::log(hi->mu_s / lo->mu_s) * k / kCurvePoints;
    if (first) mu_s[std::size_t(k)] = std::exp(x(0));
    const Eigen::VectorXd y = trend.predict(x) - less;
    for (Eigen::Index o = 0; o < less.size(); ++o)
      curve[std::size_t(o)][std::size_t(k)] += weight * y(o);
  }
}

// The observables that the experiment and every run have (or `only`), as plain vectors.
std::vector<std::string> common_observables(const SteadyState& experiment,
                                            const std::vector<SteadyStateRun>& runs,
                                            const std::vector<std::string>& only,
                                            std::vector<double>& measured,
                                            std::vector<ObservableRun>& twin) {
  std::vector<std::string> names;
  // By default the lid's packing fraction is left out where the positions' height gives
  // the same number (both are the grains' volume under the lid): counted twice it would
  // weigh twice.
  const bool from_height = std::isfinite(experiment["height_packing_fraction"]);
  for (const std::string& name : only.empty() ? experiment.names : only) {
    if (only.empty() && from_height && name == "packing_fraction") continue;
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
  for (const std::string& name : names)
    measured.push_back(experiment[name]);
  for (const SteadyStateRun& r : runs) {
    ObservableRun run{r.mu_s, r.seed, {}, r.mu_r};
    for (const std::string& name : names)
      run.values.push_back(r.state[name]);
    twin.push_back(std::move(run));
  }
  return names;
}

// A fit on the observables common_observables() picks, its `names` set to them, with the
// experiment's systematic errors where it has them.
template <class Fit>
auto fit_by_name(const SteadyState& experiment, const std::vector<SteadyStateRun>& runs,
                 const std::vector<std::string>& only, ObservableFitOptions options,
                 const Fit& fit) {
  std::vector<double> measured;
  std::vector<ObservableRun> twin;
  std::vector<std::string> names = common_observables(experiment, runs, only, measured, twin);
  if (!experiment.systematic.empty()) {
    options.experiment_systematic.clear();
    for (const std::string& name : names)
      options.experiment_systematic.push_back(experiment.systematic_of(name));
  }
  auto result = fit(measured, twin, options);
  result.names = std::move(names);
  return result;
}

std::string method_text(std::size_t observables, const std::string& variables, int degree,
                        std::size_t runs, double spare, std::size_t cross_validations,
                        bool by_friction) {
  return "Ceres generalized least squares of " + std::to_string(observables) +
         " steady-state observables against their trend in " + variables + " (degree " +
         std::to_string(degree) + ") across " + std::to_string(runs) +
         " runs, covariance from the runs' scatter about it (" + std::to_string(int(spare)) +
         " spare runs, shrunk to its diagonal)" +
         (cross_validations > 0
              ? "; cross-validated across packings on " + std::to_string(cross_validations) +
                    " runs" +
                    (by_friction ? ", carried to the fit by the error the trend predicts" : "")
              : std::string());
}

// The GLS fit of `dims` log frictions with its misfit: chi2 over observables - dims dof,
// and sqrt(chi2 / dof) when above 1, the factor the fit's errors are widened by; the
// covariance of the log frictions, so widened, split into the experiment's systematic
// errors' share and the rest, the packing's.
struct Misfitted {
  Eigen::VectorXd target;
  OneFit f;
  double dof = 0, error_scale = 1;
  Eigen::MatrixXd covariance, systematic, packing;
};
Misfitted fit_checked(const std::vector<double>& experiment, const std::vector<ObservableRun>& runs,
                      int dims, const ObservableFitOptions& options) {
  check_runs(experiment, runs, dims, options);
  Misfitted m;
  const Eigen::Index n = Eigen::Index(experiment.size());
  m.target = Eigen::Map<const Eigen::VectorXd>(experiment.data(), n);
  Target target{m.target, Eigen::VectorXd::Zero(n)};
  if (!options.experiment_systematic.empty())
    target.systematic =
        Eigen::Map<const Eigen::VectorXd>(options.experiment_systematic.data(), n).array().square();
  m.f = fit_once(target, runs, dims, options.degree);
  m.dof = double(experiment.size()) - dims;
  m.error_scale = m.dof > 0 ? std::max(1.0, std::sqrt(m.f.chi2 / m.dof)) : 1.0;
  const double widened = m.error_scale * m.error_scale;
  m.covariance = m.f.covariance * widened;
  m.systematic = systematic_share(m.f.trend, m.f.x, target.systematic) * widened;
  m.packing = m.covariance - m.systematic;
  return m;
}

}  // namespace

ObservableFit fit_friction_to_observables(const std::vector<double>& experiment,
                                          const std::vector<ObservableRun>& runs,
                                          const ObservableFitOptions& options) {
  const Misfitted m = fit_checked(experiment, runs, 1, options);
  const Eigen::VectorXd& target = m.target;
  const OneFit& f = m.f;
  ObservableFit fit;
  fit.mu_s = std::exp(f.x(0));
  fit.chi2 = f.chi2;
  fit.dof = m.dof;
  fit.error_scale = m.error_scale;
  fit.gls_sigma = std::sqrt(m.covariance(0, 0));
  fit.systematic_sigma = std::sqrt(m.systematic(0, 0));
  fit.log_mu_s_sigma = fit.gls_sigma;
  double t = student_t_975(f.trend.spare);
  fit.simulations = runs.size();
  const Eigen::VectorXd model = f.trend.predict(f.x), slope = f.trend.gradient(f.x).col(0);
  const double inflation = std::sqrt(1 + f.trend.leverage(f.x));
  for (Eigen::Index o = 0; o < target.size(); ++o) {
    fit.model.push_back(model(o));
    fit.scatter.push_back(f.trend.scatter(o));
    fit.resolution.push_back(inflation * f.trend.scatter(o) / std::abs(slope(o)));
  }
  add_curve(f.trend, runs, Eigen::VectorXd::Zero(target.size()), 1, fit.curve_mu_s, fit.curve);
  if (options.cross_validate) {
    const CrossValidation cv = cross_validate(runs, f.trend, 1, options.degree);
    fit.cross_validations = cv.count;
    fit.cross_validated_sigma = cross_validated_sigma(cv, f.trend, f.x, options)(0);
    if (cv.count > 0 && fit.cross_validated_sigma > std::sqrt(std::max(0.0, m.packing(0, 0)))) {
      fit.log_mu_s_sigma = std::hypot(fit.cross_validated_sigma, fit.systematic_sigma);
      t = student_t_975(double(cv.count));
    }
  }
  fit.mu_s_ci95 = {std::exp(f.x(0) - t * fit.log_mu_s_sigma),
                   std::exp(f.x(0) + t * fit.log_mu_s_sigma)};
  fit.method = method_text(experiment.size(), "ln mu_s", options.degree, runs.size(), f.trend.spare,
                           fit.cross_validations, options.cross_validation_by_friction);
  return fit;
}

ObservableFit fit_friction_to_steady_state(const SteadyState& experiment,
                                           const std::vector<SteadyStateRun>& runs,
                                           const ObservableFitOptions& options,
                                           const std::vector<std::string>& only) {
  return fit_by_name(experiment, runs, only, options,
                     [](const auto& measured, const auto& twin, const auto& with) {
                       return fit_friction_to_observables(measured, twin, with);
                     });
}

JointObservableFit fit_frictions_to_observables(const std::vector<double>& experiment,
                                                const std::vector<ObservableRun>& runs,
                                                const ObservableFitOptions& options) {
  const Misfitted m = fit_checked(experiment, runs, 2, options);
  const Eigen::VectorXd& target = m.target;
  const OneFit& f = m.f;
  JointObservableFit fit;
  fit.mu_s = std::exp(f.x(0));
  fit.mu_r = std::exp(f.x(1));
  fit.chi2 = f.chi2;
  fit.dof = m.dof;
  fit.error_scale = m.error_scale;
  Eigen::Matrix2d c = m.covariance;
  fit.gls_sigma = {std::sqrt(c(0, 0)), std::sqrt(c(1, 1))};
  fit.systematic_sigma = {std::sqrt(m.systematic(0, 0)), std::sqrt(m.systematic(1, 1))};
  double dof = f.trend.spare;
  fit.simulations = runs.size();
  const Eigen::VectorXd model = f.trend.predict(f.x);
  for (Eigen::Index o = 0; o < target.size(); ++o) {
    fit.model.push_back(model(o));
    fit.scatter.push_back(f.trend.scatter(o));
  }
  // Each log friction's packing error is the larger of the fit's and the cross-validation's,
  // the experiment's systematic share beside it; the correlation is the fit's.
  if (options.cross_validate) {
    const CrossValidation cv = cross_validate(runs, f.trend, 2, options.degree);
    const LogFriction sigma = cross_validated_sigma(cv, f.trend, f.x, options);
    fit.cross_validations = cv.count;
    fit.cross_validated_sigma = {sigma(0), sigma(1)};
    const Eigen::Vector2d packing = m.packing.diagonal().cwiseMax(1e-300).cwiseSqrt();
    if (cv.count > 0 && (sigma(0) > packing(0) || sigma(1) > packing(1))) {
      Eigen::Matrix2d scale = Eigen::Matrix2d::Zero();
      for (int d = 0; d < 2; ++d)
        scale(d, d) = std::max(1.0, sigma(d) / packing(d));
      c = scale * m.packing * scale + m.systematic;
      dof = double(cv.count);
    }
  }
  const double t = student_t_975(dof);
  fit.log_covariance = {c(0, 0), c(0, 1), c(1, 0), c(1, 1)};
  fit.correlation = c(0, 1) / std::sqrt(c(0, 0) * c(1, 1));
  fit.mu_s_ci95 = {std::exp(f.x(0) - t * std::sqrt(c(0, 0))),
                   std::exp(f.x(0) + t * std::sqrt(c(0, 0)))};
  fit.mu_r_ci95 = {std::exp(f.x(1) - t * std::sqrt(c(1, 1))),
                   std::exp(f.x(1) + t * std::sqrt(c(1, 1)))};
  // chi-square with 2 dof at 95 %: -2 ln 0.05; Student's t's excess over the normal's 1.96
  // for the finite dof behind the covariance.
  const double radius = std::sqrt(-2 * std::log(0.05)) * t / 1.959964;
  const Eigen::Matrix2d l = c.llt().matrixL();
  for (int k = 0; k <= 72; ++k) {
    const double a = 2 * M_PI * k / 72;
    const Eigen::Vector2d x = f.x + radius * l * Eigen::Vector2d(std::cos(a), std::sin(a));
    fit.region95.push_back({std::exp(x(0)), std::exp(x(1))});
  }
  fit.method =
      method_text(experiment.size(), "(ln mu_s, ln mu_r)", options.degree, runs.size(),
                  f.trend.spare, fit.cross_validations, options.cross_validation_by_friction);
  return fit;
}

JointObservableFit fit_frictions_to_steady_state(const SteadyState& experiment,
                                                 const std::vector<SteadyStateRun>& runs,
                                                 const ObservableFitOptions& options,
                                                 const std::vector<std::string>& only) {
  return fit_by_name(experiment, runs, only, options,
                     [](const auto& measured, const auto& twin, const auto& with) {
                       return fit_frictions_to_observables(measured, twin, with);
                     });
}

namespace {

// The observables common_observables() picks in every segment, in the first one's order.
std::vector<std::string> observables_of_every_segment(
    const std::vector<SteadyStateSegment>& segments, const std::vector<std::string>& only) {
  std::vector<std::string> names;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    std::vector<double> measured;
    std::vector<ObservableRun> twin;
    const std::vector<std::string> here =
        common_observables(segments[k].experiment, segments[k].runs, only, measured, twin);
    if (k == 0) {
      names = here;
      continue;
    }
    names.erase(std::remove_if(names.begin(), names.end(),
                               [&](const std::string& n) {
                                 return std::find(here.begin(), here.end(), n) == here.end();
                               }),
                names.end());
  }
  if (names.empty()) throw Error("segmented fit: no observable in every segment");
  return names;
}

// One segment as the fit takes it: its target, its runs and their trend.
struct Segment {
  Target target;
  std::vector<ObservableRun> runs;
  Trend trend;
};
Segment prepared_segment(const SteadyStateSegment& s, const std::vector<std::string>& names,
                         const ObservableFitOptions& options) {
  Segment p;
  std::vector<double> measured;
  common_observables(s.experiment, s.runs, names, measured, p.runs);
  ObservableFitOptions with = options;
  with.experiment_systematic.clear();
  for (const std::string& name : names)
    with.experiment_systematic.push_back(s.experiment.systematic_of(name));
  check_runs(measured, p.runs, 1, with);
  const Eigen::Index n = Eigen::Index(names.size());
  p.target.value = Eigen::Map<const Eigen::VectorXd>(measured.data(), n);
  p.target.systematic =
      Eigen::Map<const Eigen::VectorXd>(with.experiment_systematic.data(), n).array().square();
  p.trend = fit_trend(p.runs, 1, options.degree);
  return p;
}

}  // namespace

SegmentedFit fit_friction_by_segments(const std::vector<SteadyStateSegment>& segments,
                                      const ObservableFitOptions& options,
                                      const std::vector<std::string>& only) {
  if (segments.size() < 3) {
    throw Error("segmented fit: " + std::to_string(segments.size()) +
                " segments, need at least 3 (their scatter is the fit's error)");
  }
  SegmentedFit fit;
  fit.names = observables_of_every_segment(segments, only);
  std::vector<Segment> prepared;
  for (const SteadyStateSegment& s : segments)
    prepared.push_back(prepared_segment(s, fit.names, options));
  // One cycle's scatter about the trend, pooled over the segments' spare runs.
  Eigen::MatrixXd pooled =
      Eigen::MatrixXd::Zero(prepared[0].trend.sample.rows(), prepared[0].trend.sample.cols());
  double spare = 0;
  for (const Segment& p : prepared) {
    pooled += p.trend.sample * p.trend.spare;
    spare += p.trend.spare;
  }
  pooled /= spare;
  const Eigen::MatrixXd covariance = shrunk_covariance(pooled, spare);
  const double n = double(segments.size());
  double sum = 0, systematic = 0;
  Eigen::VectorXd experiment_systematic = Eigen::VectorXd::Zero(pooled.rows());
  fit.offset.resize(fit.names.size());
  for (Segment& p : prepared) {
    p.trend.covariance = covariance;
    const OneFit f = fit_to_trend(p.target, p.runs, 1, p.trend);
    fit.segment_mu_s.push_back(std::exp(f.x(0)));
    fit.segment_log_sigma.push_back(std::sqrt(f.covariance(0, 0)));
    sum += f.x(0);
    systematic += std::sqrt(systematic_share(f.trend, f.x, p.target.systematic)(0, 0));
    experiment_systematic += p.target.systematic.cwiseSqrt() / n;
    add_curve(f.trend, p.runs, p.target.value, 1 / n, fit.curve_mu_s, fit.curve_offset);
    for (const ObservableRun& r : p.runs) {
      fit.run_mu_s.push_back(r.mu_s);
      for (std::size_t o = 0; o < fit.names.size(); ++o)
        fit.offset[o].push_back(r.values[o] - p.target.value(Eigen::Index(o)));
    }
  }
  const double mean = sum / n;
  double spread2 = 0;
  for (double mu : fit.segment_mu_s)
    spread2 += std::pow(std::log(mu) - mean, 2) / (n - 1);
  fit.scatter_sigma = std::sqrt(spread2 / n);
  fit.systematic_sigma = systematic / n;
  fit.log_mu_s_sigma = std::hypot(fit.scatter_sigma, fit.systematic_sigma);
  const double t = student_t_975(n - 1);
  fit.mu_s = std::exp(mean);
  fit.mu_s_ci95 = {std::exp(mean - t * fit.log_mu_s_sigma),
                   std::exp(mean + t * fit.log_mu_s_sigma)};
  for (Eigen::Index o = 0; o < pooled.rows(); ++o) {
    fit.scatter.push_back(std::sqrt(pooled(o, o)));
    fit.offset_error.push_back(
        std::hypot(fit.scatter.back() / std::sqrt(n), experiment_systematic(o)));
  }
  fit.runs = prepared[0].runs.size();
  fit.method = "the mean of " + std::to_string(segments.size()) + " segments' Ceres GLS fits of " +
               std::to_string(fit.names.size()) + " one-cycle observables against their trend in " +
               "ln mu_s (degree " + std::to_string(options.degree) + ") across " +
               std::to_string(fit.runs) + " runs each, covariance pooled over the segments (" +
               std::to_string(int(spare)) + " spare runs, shrunk to its diagonal); its error " +
               "the segments' scatter, Student's t for " + std::to_string(segments.size() - 1) +
               " dof";
  return fit;
}

}  // namespace granmem
