#include "granmem/calibration/friction_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "ceres_variance.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

double normal_cdf(double x) {
  return 0.5 * std::erfc(-x * M_SQRT1_2);
}

// The summaries: thresholds of log(dr) for each group of displacements (one group pooling
// the window, or one per cycle), `levels` per group.
struct SummaryLevels {
  std::vector<double> tau;          // groups x levels, log(dr)
  std::vector<std::int64_t> cycle;  // per group: its cycle, or 0 for the pooled window
  Eigen::Index levels = 0;
  // The group of a displacement of cycle `c`, or -1 when none holds it.
  Eigen::Index group(std::int64_t c) const {
    if (cycle.size() == 1 && cycle[0] == 0) return 0;
    const auto it = std::find(cycle.begin(), cycle.end(), c);
    return it == cycle.end() ? -1 : Eigen::Index(it - cycle.begin());
  }
  Eigen::Index size() const { return Eigen::Index(tau.size()); }
};

// A sample's smoothed CDFs at the thresholds, kept as sums per grain so that whole grains
// can be resampled: F_j = sum_g S_gj / sum_g n_g,group(j).
struct GrainSums {
  Eigen::MatrixXd sum;    // grains x summaries
  Eigen::MatrixXd count;  // grains x groups: values per grain in each group
  Eigen::Index levels = 1;
  GrainSums(std::size_t grains, const SummaryLevels& l)
      : sum(Eigen::MatrixXd::Zero(Eigen::Index(grains), l.size())),
        count(Eigen::MatrixXd::Zero(Eigen::Index(grains), Eigen::Index(l.cycle.size()))),
        levels(l.levels) {}
  // The CDFs of grains weighted by `weight` (ones: the sample itself).
  Eigen::VectorXd cdf(const Eigen::VectorXd& weight) const {
    const Eigen::RowVectorXd s = weight.transpose() * sum, n = weight.transpose() * count;
    Eigen::VectorXd f(s.size());
    for (Eigen::Index j = 0; j < s.size(); ++j)
      f(j) = s(j) / n(j / levels);
    return f;
  }
  Eigen::VectorXd cdf() const { return cdf(Eigen::VectorXd::Ones(sum.rows())); }
};

// Adds log(value) of grain `grain` (compact index) in group `group` to the sums.
void add_value(GrainSums& s, std::size_t grain, Eigen::Index group, double log_value,
               const SummaryLevels& l, double width) {
  for (Eigen::Index j = group * l.levels; j < (group + 1) * l.levels; ++j)
    s.sum(Eigen::Index(grain), j) += normal_cdf((l.tau[std::size_t(j)] - log_value) / width);
  s.count(Eigen::Index(grain), group) += 1;
}

// Compact grain indices 0..G-1 for the grain labels of a sample.
std::vector<std::size_t> compact(const std::vector<std::size_t>& grain, std::size_t* count) {
  std::map<std::size_t, std::size_t> index;
  std::vector<std::size_t> out(grain.size());
  for (std::size_t k = 0; k < grain.size(); ++k)
    out[k] = index.emplace(grain[k], index.size()).first->second;
  *count = index.size();
  return out;
}

// Covariance of the CDF values over resamples of whole grains.
Eigen::MatrixXd bootstrap_covariance(const GrainSums& s, std::size_t resamples, Random& random) {
  const Eigen::Index g = s.sum.rows(), j = s.sum.cols();
  Eigen::MatrixXd f(Eigen::Index(resamples), j);
  Eigen::VectorXd weight(g);
  for (std::size_t b = 0; b < resamples; ++b) {
    weight.setZero();
    for (Eigen::Index k = 0; k < g; ++k)
      weight(Eigen::Index(random.uniform() * double(g))) += 1;
    f.row(Eigen::Index(b)) = s.cdf(weight).transpose();
  }
  const Eigen::MatrixXd centred = f.rowwise() - f.colwise().mean();
  return centred.transpose() * centred / double(resamples - 1);
}

// The simulated runs' smoothed CDFs with the noise model, and their polynomial in
// log(mu_s) across the runs.
class SimulatedSummaries {
 public:
  SimulatedSummaries(const std::vector<FrictionRun>& runs, const SummaryLevels& tau,
                     const FrictionFitOptions& o)
      : runs_(runs), tau_(tau), o_(o) {
    Random random(o.seed + 1);
    const std::size_t copies = o.noise == NoiseModel::none ? 1 : o.noise_replicas;
    for (const FrictionRun& r : runs) {
      Eigen::MatrixXd z(r.observables.displacement.rows() * Eigen::Index(copies), 3);
      for (Eigen::Index k = 0; k < z.size(); ++k)
        z.data()[k] = random.normal();
      normals_.push_back(std::move(z));
    }
    const Eigen::Index k = Eigen::Index(runs.size()), p = o.degree + 1;
    for (const FrictionRun& r : runs)
      centre_ += std::log(r.mu_s) / double(k);
    Eigen::MatrixXd x(k, p);
    for (Eigen::Index i = 0; i < k; ++i)
      x.row(i) = powers(std::log(runs[std::size_t(i)].mu_s));
    normal_inverse_ = (x.transpose() * x).inverse();
    projector_ = normal_inverse_ * x.transpose();
  }

  // Sums per grain of run `k` at noise `sigma`.
  GrainSums run_sums(std::size_t k, double sigma) const {
    const CycleObservables& o = runs_[k].observables;
    std::size_t grains = 0;
    const std::vector<std::size_t> g = compact(o.dr_grain, &grains);
    GrainSums s(grains, tau_);
    const Eigen::MatrixXd& z = normals_[k];
    const Eigen::Index n = o.displacement.rows();
    const Eigen::Index copies = z.rows() / std::max<Eigen::Index>(n, 1);
    const Eigen::RowVector3d scale = M_SQRT2 * sigma * o_.noise_shape.transpose();
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index group = tau_.group(o.dr_cycle.empty() ? 0 : o.dr_cycle[std::size_t(i)]);
      if (group < 0) continue;
      for (Eigen::Index c = 0; c < copies; ++c) {
        const Eigen::RowVector3d d =
            o.displacement.row(i) + scale.cwiseProduct(z.row(i * copies + c));
        const double dr = d.norm();
        if (dr > 0) add_value(s, g[std::size_t(i)], group, std::log(dr), tau_, o_.kernel_width);
      }
    }
    if ((s.count.colwise().sum().array() == 0).any()) {
      throw Error("friction fit: the run at mu_s " + std::to_string(runs_[k].mu_s) +
                  " has no displacement in a cycle the experiment has");
    }
    return s;
  }

  // Runs x thresholds, cached for the last sigma (Ceres varies one parameter at a time).
  const Eigen::MatrixXd& run_cdfs(double sigma) const {
    if (sigma != cached_sigma_ || cached_.size() == 0) {
      cached_.resize(Eigen::Index(runs_.size()), tau_.size());
      for (std::size_t k = 0; k < runs_.size(); ++k)
        cached_.row(Eigen::Index(k)) = run_sums(k, sigma).cdf().transpose();
      cached_sigma_ = sigma;
    }
    return cached_;
  }

  Eigen::VectorXd predict(double log_mu, double sigma) const {
    return (powers(log_mu) * projector_ * run_cdfs(sigma)).transpose();
  }

  // The covariance of the runs' residuals about the polynomial, sum_k r_k r_k^T / (runs -
  // coefficients): sampling and realization noise together; empty without spare runs.
  Eigen::MatrixXd residual_covariance(double sigma) const {
    const Eigen::MatrixXd& f = run_cdfs(sigma);
    const Eigen::Index k = f.rows(), spare = k - (o_.degree + 1);
    if (spare <= 0) return {};
    Eigen::MatrixXd x(k, o_.degree + 1);
    for (Eigen::Index i = 0; i < k; ++i)
      x.row(i) = powers(std::log(runs_[std::size_t(i)].mu_s));
    const Eigen::MatrixXd r = f - x * (projector_ * f);
    return r.transpose() * r / double(spare);
  }

  // Variance of the polynomial's prediction over that of one run: how much the fit across
  // the runs averages their sampling noise away.
  double leverage(double log_mu) const {
    const Eigen::RowVectorXd x = powers(log_mu);
    return (x * normal_inverse_ * x.transpose())(0, 0);
  }

 private:
  Eigen::RowVectorXd powers(double log_mu) const {
    Eigen::RowVectorXd x(o_.degree + 1);
    for (int p = 0; p <= o_.degree; ++p)
      x(p) = std::pow(log_mu - centre_, p);
    return x;
  }

  const std::vector<FrictionRun>& runs_;
  const SummaryLevels& tau_;
  const FrictionFitOptions& o_;
  std::vector<Eigen::MatrixXd> normals_;
  double centre_ = 0;
  Eigen::MatrixXd normal_inverse_, projector_;
  mutable Eigen::MatrixXd cached_;
  mutable double cached_sigma_ = std::numeric_limits<double>::quiet_NaN();
};

// Whitened residuals L^-1 (F_sim(mu, sigma) - F_exp), C = L L^T.
struct SummaryResidual {
  const SimulatedSummaries* model;
  Eigen::VectorXd target;
  Eigen::MatrixXd whitening;
  bool operator()(double const* const* p, double* r) const {
    const Eigen::VectorXd d = model->predict(p[0][0], p[1][0]) - target;
    Eigen::Map<Eigen::VectorXd>(r, d.size()) = whitening * d;
    return true;
  }
};

std::string format_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

}  // namespace

std::vector<double> noisy_dr(const CycleObservables& simulated, const Eigen::Vector3d& noise_shape,
                             double sigma, std::uint64_t seed) {
  Random random(seed);
  std::vector<double> dr;
  dr.reserve(std::size_t(simulated.displacement.rows()));
  for (Eigen::Index i = 0; i < simulated.displacement.rows(); ++i) {
    Eigen::Vector3d d = simulated.displacement.row(i).transpose();
    if (sigma > 0) {
      for (int a = 0; a < 3; ++a)
        d(a) += M_SQRT2 * sigma * noise_shape(a) * random.normal();
    }
    dr.push_back(d.norm());
  }
  return dr;
}

namespace {

// ln(mu_s) over the runs, after checking that they can carry a polynomial of the degree.
std::pair<double, double> log_friction_range(const std::vector<FrictionRun>& runs,
                                             const FrictionFitOptions& o) {
  if (o.degree < 1) throw Error("friction fit: the polynomial degree must be at least 1");
  if (runs.size() < std::size_t(o.degree) + 1) {
    throw Error("friction fit: " + std::to_string(runs.size()) + " simulated runs, need at least " +
                std::to_string(o.degree + 1) + " (a polynomial of degree " +
                std::to_string(o.degree) + " in log mu_s)");
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const FrictionRun& r : runs) {
    if (!(r.mu_s > 0)) throw Error("friction fit: mu_s must be positive");
    if (r.observables.dr.empty()) throw Error("friction fit: a simulated run has no displacement");
    lo = std::min(lo, std::log(r.mu_s));
    hi = std::max(hi, std::log(r.mu_s));
  }
  if (!(hi > lo)) throw Error("friction fit: the runs must differ in mu_s");
  if (o.probabilities.empty()) throw Error("friction fit: no CDF levels");
  return {lo, hi};
}

// The experiment's summaries: the quantiles of log(dr) (over the pooled window, or each of
// its cycles) where the CDFs are compared, the smoothed CDF there, and its sampling
// covariance (a bootstrap over grains).
struct MeasuredSummaries {
  SummaryLevels tau;
  std::vector<double> log_dr;
  Eigen::VectorXd target;
  Eigen::MatrixXd covariance;
};

MeasuredSummaries measured_summaries(const CycleObservables& experiment,
                                     const FrictionFitOptions& o, Random& random) {
  MeasuredSummaries m;
  std::map<std::int64_t, std::vector<double>> by_cycle;
  std::vector<std::size_t> grain_of;
  std::vector<std::int64_t> cycle_of;
  for (std::size_t k = 0; k < experiment.dr.size(); ++k) {
    if (experiment.dr[k] > 0 && std::isfinite(experiment.dr[k])) {
      m.log_dr.push_back(std::log(experiment.dr[k]));
      grain_of.push_back(experiment.dr_grain[k]);
      cycle_of.push_back(o.per_cycle && !experiment.dr_cycle.empty() ? experiment.dr_cycle[k] : 0);
      by_cycle[cycle_of.back()].push_back(m.log_dr.back());
    }
  }
  m.tau.levels = Eigen::Index(o.probabilities.size());
  for (const auto& [c, values] : by_cycle) {
    if (values.size() < 10 * o.probabilities.size()) {
      throw Error("friction fit: " + std::to_string(values.size()) + " measured displacements" +
                  (c ? " in cycle " + std::to_string(c) : std::string()) + ", too few for " +
                  std::to_string(o.probabilities.size()) + " CDF levels");
    }
    m.tau.cycle.push_back(c);
    for (double p : o.probabilities)
      m.tau.tau.push_back(quantile(values, p));
  }
  if (by_cycle.empty()) throw Error("friction fit: no measured displacement");
  std::size_t grains = 0;
  const std::vector<std::size_t> g = compact(grain_of, &grains);
  GrainSums sums(grains, m.tau);
  for (std::size_t k = 0; k < m.log_dr.size(); ++k)
    add_value(sums, g[k], m.tau.group(cycle_of[k]), m.log_dr[k], m.tau, o.kernel_width);
  m.target = sums.cdf();
  m.covariance = bootstrap_covariance(sums, o.bootstrap, random);
  return m;
}

// The start of the fit: the best point of a grid (the experiment's errors only), since the
// cost need not be convex in the noise.
void grid_start(const SimulatedSummaries& model, const MeasuredSummaries& measured,
                const FrictionFitOptions& o, double lo, double hi, double& log_mu, double& sigma) {
  const Eigen::VectorXd weight = measured.covariance.diagonal().cwiseMax(1e-12).cwiseInverse();
  std::vector<double> sigmas{sigma};
  if (o.noise == NoiseModel::fitted) {
    const double median = std::exp(quantile(measured.log_dr, 0.5));
    const double top = median / o.noise_shape.norm();
    sigmas.clear();
    for (int k = 0; k <= 16; ++k)
      sigmas.push_back(top * k / 16.0);
  }
  double best = std::numeric_limits<double>::infinity();
  for (double s : sigmas) {
    for (int k = 0; k <= 24; ++k) {
      const double m = lo + (hi - lo) * k / 24.0;
      const Eigen::VectorXd d = model.predict(m, s) - measured.target;
      const double c = d.cwiseProduct(d).dot(weight);
      if (c < best) {
        best = c;
        log_mu = m;
        sigma = s;
      }
    }
  }
}

// The generalized least-squares fit in two rounds: the simulation's covariance depends on
// the noise and, through the polynomial's leverage, on mu_s; both are taken at the previous
// round's fit. Sets the fit's convergence, chi2, error of ln(mu_s) and of the noise, and
// returns the share of the summaries' variance that comes from the runs' scatter.
double least_squares_rounds(const SimulatedSummaries& model, const MeasuredSummaries& measured,
                            const FrictionFitOptions& o, std::size_t run_count, double lo,
                            double hi, Random& random, double& log_mu, double& sigma,
                            FrictionFit& fit) {
  const Eigen::Index nj = measured.tau.size();
  const bool fit_noise = o.noise == NoiseModel::fitted;
  ceres::Problem::Options po;
  double estimated_share = 0;
  for (int round = 0; round < 2; ++round) {
    Eigen::MatrixXd run_cov = Eigen::MatrixXd::Zero(nj, nj);
    for (std::size_t k = 0; k < run_count; ++k)
      run_cov +=
          bootstrap_covariance(model.run_sums(k, sigma), o.bootstrap, random) / double(run_count);
    // A packing is one realization of a chaotic system: runs that differ only in friction
    // scatter about any smooth trend by more than their grains' sampling error (a run may
    // settle into a nearly reversible cycle, or not), and mostly along one direction (all
    // CDF values at once). That excess, measured on the runs' residuals about the
    // polynomial, is the realization noise; the experiment's packing has it too.
    Eigen::MatrixXd excess = Eigen::MatrixXd::Zero(nj, nj);
    const Eigen::MatrixXd residual = model.residual_covariance(sigma);
    if (residual.size()) {
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(residual - run_cov);
      excess = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
               eigen.eigenvectors().transpose();
      fit.overdispersion = std::max(1.0, residual.trace() / run_cov.trace());
    }
    const double leverage = model.leverage(log_mu);
    Eigen::MatrixXd cov = measured.covariance + excess + leverage * (run_cov + excess);
    estimated_share = (1 + leverage) * excess.trace() / cov.trace();
    cov.diagonal().array() += 1e-12;
    const Eigen::MatrixXd whitening = cov.llt().matrixL().solve(Eigen::MatrixXd::Identity(nj, nj));

    ceres::Problem problem(po);
    auto* cost = new ceres::DynamicNumericDiffCostFunction<SummaryResidual, ceres::CENTRAL>(
        new SummaryResidual{&model, measured.target, whitening});
    cost->AddParameterBlock(1);
    cost->AddParameterBlock(1);
    cost->SetNumResiduals(int(nj));
    problem.AddResidualBlock(cost, nullptr, &log_mu, &sigma);
    problem.SetParameterLowerBound(&log_mu, 0, lo);
    problem.SetParameterUpperBound(&log_mu, 0, hi);
    if (fit_noise) {
      problem.SetParameterLowerBound(&sigma, 0, 0.0);
    } else {
      problem.SetParameterBlockConstant(&sigma);
    }
    ceres::Solver::Options so;
    so.max_num_iterations = 100;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    fit.converged = summary.termination_type == ceres::CONVERGENCE;
    fit.chi2 = 2 * summary.final_cost;

    if (round == 1) {
      std::vector<double*> parameters{&log_mu};
      if (fit_noise) parameters.push_back(&sigma);
      const std::vector<double> variance = parameter_variances(problem, parameters);
      const double var_mu = variance[0], var_sigma = fit_noise ? variance[1] : std::nan("");
      fit.dof = double(nj) - (fit_noise ? 2.0 : 1.0);
      fit.error_scale = fit.dof > 0 ? std::max(1.0, std::sqrt(fit.chi2 / fit.dof)) : 1.0;
      fit.log_mu_s_sigma = std::sqrt(var_mu) * fit.error_scale;
      fit.noise_sigma_error = fit_noise ? std::sqrt(var_sigma) * fit.error_scale : 0.0;
    }
  }
  return estimated_share;
}

// Cross-validation across packings: the summaries' covariance, estimated from a few spare
// runs, cannot see every direction in which one packing differs from another; fitting twin
// runs of known friction with the other seeds' runs measures how far a realization moves
// the fitted mu_s. The interval takes the larger of the two errors (and then Student's t
// with as many dof as runs tested).
void cross_validate(const std::vector<FrictionRun>& runs, const FrictionFitOptions& o,
                    FrictionFit& fit, double& t) {
  FrictionFitOptions inner = o;
  inner.cross_validate = false;
  inner.noise = NoiseModel::none;  // simulated against simulated: no locating noise
  double sum2 = 0;
  for (const FrictionRun& held_out : runs) {
    const double m = std::log(held_out.mu_s);
    std::vector<FrictionRun> others;
    double others_lo = std::numeric_limits<double>::infinity(), others_hi = -others_lo;
    for (const FrictionRun& r : runs) {
      if (r.seed == held_out.seed) continue;
      others.push_back(r);
      others_lo = std::min(others_lo, std::log(r.mu_s));
      others_hi = std::max(others_hi, std::log(r.mu_s));
    }
    // Interior frictions only: at the range's ends the bounded fit cannot err outwards.
    if (others.size() < std::size_t(o.degree) + 1 || !(others_lo < m && m < others_hi)) continue;
    try {
      const FrictionFit f = fit_friction(held_out.observables, others, inner);
      sum2 += std::pow(std::log(f.mu_s) - m, 2);
      ++fit.cross_validations;
    } catch (const Error&) {
      // too few distinct frictions among the others: no test from this run
    }
  }
  if (fit.cross_validations > 0) {
    fit.cross_validated_sigma = std::sqrt(sum2 / double(fit.cross_validations));
    if (fit.cross_validated_sigma > fit.log_mu_s_sigma) {
      fit.log_mu_s_sigma = fit.cross_validated_sigma;
      t = student_t_975(double(fit.cross_validations));
    }
  }
}

// The curves of the figure: thresholds, the experiment's CDF with its errors, the model's
// at the fit and each run's.
void fitted_curves(const SimulatedSummaries& model, const MeasuredSummaries& measured,
                   double log_mu, double sigma, FrictionFit& fit) {
  const Eigen::Index nj = measured.tau.size();
  for (Eigen::Index j = 0; j < nj; ++j) {
    fit.thresholds.push_back(std::exp(measured.tau.tau[std::size_t(j)]));
    fit.threshold_cycle.push_back(measured.tau.cycle[std::size_t(j / measured.tau.levels)]);
  }
  const Eigen::VectorXd at_fit = model.predict(log_mu, sigma);
  for (Eigen::Index j = 0; j < nj; ++j) {
    fit.experiment_cdf.push_back(measured.target(j));
    fit.experiment_error.push_back(std::sqrt(measured.covariance(j, j)));
    fit.model_cdf.push_back(at_fit(j));
  }
  const Eigen::MatrixXd& per_run = model.run_cdfs(sigma);
  for (Eigen::Index k = 0; k < per_run.rows(); ++k) {
    const Eigen::VectorXd row = per_run.row(k).transpose();
    fit.run_cdf.emplace_back(row.data(), row.data() + nj);
  }
}

std::string method_text(const FrictionFitOptions& o, const FrictionFit& fit,
                        const SummaryLevels& tau, double spare, double effective_dof) {
  return "Ceres generalized least squares on the smoothed CDF of log(dr) at the experiment's " +
         std::to_string(tau.levels) + " quantiles" +
         (o.per_cycle ? " of each of its " + std::to_string(tau.cycle.size()) + " cycles"
                      : std::string(" of the pooled window")) +
         ", covariance from a bootstrap over grains of the experiment and of the "
         "runs plus the realization noise measured on the runs' scatter about the fit across "
         "frictions (x" +
         format_number(fit.overdispersion) + " the sampling variance, from " +
         format_number(spare) + " spare runs)" +
         "; 95 % interval from Ceres' covariance of ln(mu_s)" +
         (effective_dof > 0
              ? ", Student's t with " + format_number(effective_dof) + " effective dof"
              : std::string()) +
         std::string(fit.error_scale > 1 ? ", widened by sqrt(chi2/dof)" : "") +
         (fit.cross_validations > 0
              ? "; cross-validated across packings (" + std::to_string(fit.cross_validations) +
                    " twin runs of known mu_s fitted with the other seeds' runs: RMS error " +
                    format_number(fit.cross_validated_sigma) + " in ln mu_s" +
                    (fit.cross_validated_sigma >= fit.log_mu_s_sigma
                         ? ", which sets the interval, Student's t with " +
                               std::to_string(fit.cross_validations) + " dof)"
                         : ", within Ceres' error)")
              : std::string()) +
         (o.noise == NoiseModel::fitted ? "; locating noise fitted jointly" : "");
}

}  // namespace

FrictionFit fit_friction(const CycleObservables& experiment, const std::vector<FrictionRun>& runs,
                         const FrictionFitOptions& options) {
  const FrictionFitOptions& o = options;
  const auto [lo, hi] = log_friction_range(runs, o);
  Random random(o.seed);
  const MeasuredSummaries measured = measured_summaries(experiment, o, random);
  const SimulatedSummaries model(runs, measured.tau, o);
  double log_mu = 0.5 * (lo + hi);
  double sigma = o.noise == NoiseModel::fixed ? o.noise_sigma : 0.0;
  grid_start(model, measured, o, lo, hi, log_mu, sigma);

  FrictionFit fit;
  const double estimated_share =
      least_squares_rounds(model, measured, o, runs.size(), lo, hi, random, log_mu, sigma, fit);
  fit.mu_s = std::exp(log_mu);
  // The realization noise is estimated from the runs' spare degrees of freedom, the
  // bootstrap's part is known well: Satterthwaite's effective dof of their sum sets
  // Student's multiplier (few spare runs and a large realization share: a wider interval).
  const double spare = double(runs.size()) - double(o.degree + 1);
  const double effective_dof =
      estimated_share > 0 && spare > 0 ? spare / (estimated_share * estimated_share) : 0.0;
  double t = student_t_975(effective_dof);
  if (o.cross_validate) cross_validate(runs, o, fit, t);
  fit.mu_s_ci95 = {std::exp(log_mu - t * fit.log_mu_s_sigma),
                   std::exp(log_mu + t * fit.log_mu_s_sigma)};
  fit.noise_sigma = sigma;
  fit.simulations = runs.size();
  fitted_curves(model, measured, log_mu, sigma, fit);
  fit.method = method_text(o, fit, measured.tau, spare, effective_dof);
  return fit;
}

}  // namespace granmem
