#include "granmem/calibration/friction_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/random.hpp"

namespace granmem {
namespace {

// Synthetic end-of-cycle displacements of a packing whose typical displacement falls with
// friction as mu^-0.5 (log-normal magnitudes, isotropic directions), `grains` grains over
// `cycles` cycles; `realization` scales a whole run, as one packing differs from another.
CycleObservables synthetic_run(double mu, std::size_t grains, int cycles, double realization,
                               Random& r) {
  CycleObservables o;
  o.diameter = 0.005;
  std::vector<Eigen::Vector3d> d;
  for (int c = 0; c < cycles; ++c) {
    for (std::size_t g = 0; g < grains; ++g) {
      const double size =
          0.004 * realization * std::pow(mu / 0.2, -0.5) * std::exp(0.8 * r.normal());
      Eigen::Vector3d u(r.normal(), r.normal(), r.normal());
      d.push_back(size * u.normalized());
      o.dr_grain.push_back(g);
    }
  }
  o.displacement.resize(Eigen::Index(d.size()), 3);
  for (std::size_t k = 0; k < d.size(); ++k) {
    o.displacement.row(Eigen::Index(k)) = d[k].transpose();
    o.dr.push_back(d[k].norm());
  }
  return o;
}

// Adds the locating noise the fit models: sqrt(2) sigma shape per component.
void add_noise(CycleObservables& o, const Eigen::Vector3d& shape, double sigma, Random& r) {
  for (Eigen::Index i = 0; i < o.displacement.rows(); ++i) {
    for (int a = 0; a < 3; ++a)
      o.displacement(i, a) += M_SQRT2 * sigma * shape(a) * r.normal();
    o.dr[std::size_t(i)] = o.displacement.row(i).norm();
  }
}

std::vector<FrictionRun> series(const std::vector<double>& mu, double scatter, Random& r) {
  std::vector<FrictionRun> runs;
  for (double m : mu)
    runs.push_back({m, synthetic_run(m, 300, 5, std::exp(scatter * r.normal()), r)});
  return runs;
}

TEST(FrictionFit, RecoversAKnownFrictionWithinItsInterval) {
  const std::vector<double> mu{0.05, 0.1, 0.2, 0.4, 0.8};
  int inside = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Random r(seed);
    const double truth = 0.05 * std::exp(std::log(16.0) * (0.2 + 0.6 * r.uniform()));
    const CycleObservables experiment = synthetic_run(truth, 300, 5, 1.0, r);
    const FrictionFit fit = fit_friction(experiment, series(mu, 0.0, r), {});
    EXPECT_TRUE(fit.converged);
    EXPECT_NEAR(std::log(fit.mu_s / truth), 0.0, 0.25) << "seed " << seed;
    EXPECT_LT(fit.mu_s_ci95[1] / fit.mu_s_ci95[0], 1.8);
    if (fit.mu_s_ci95[0] <= truth && truth <= fit.mu_s_ci95[1]) ++inside;
    EXPECT_EQ(fit.simulations, mu.size());
  }
  EXPECT_GE(inside, 8);  // 95 % intervals: 9.5 of 10 expected
}

TEST(FrictionFit, RealizationScatterWidensTheInterval) {
  // Runs scattered by 30 % about the trend, as small packings are: the fit measures that
  // scatter and widens its interval. (It is not yet wide enough: the truth falls inside
  // 5 times in 10 here; see docs/CALIBRATION.md.)
  const std::vector<double> mu{0.05, 0.08, 0.12, 0.2, 0.3, 0.5, 0.8};
  double scale = 0, width_scattered = 0, width_clean = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Random r(100 + seed);
    const double truth = 0.15;
    const CycleObservables experiment = synthetic_run(truth, 300, 5, 1.0, r);
    const FrictionFit scattered = fit_friction(experiment, series(mu, 0.3, r), {});
    const FrictionFit clean = fit_friction(experiment, series(mu, 0.0, r), {});
    scale += scattered.overdispersion / 10;
    width_scattered += std::log(scattered.mu_s_ci95[1] / scattered.mu_s_ci95[0]) / 10;
    width_clean += std::log(clean.mu_s_ci95[1] / clean.mu_s_ci95[0]) / 10;
  }
  EXPECT_GT(scale, 3.0);
  EXPECT_GT(width_scattered, 1.5 * width_clean);
}

TEST(FrictionFit, FitsTheLocatingNoiseJointly) {
  // Scans: each located position is off by sigma = 0.05 voxel per axis, voxels 1/12 of
  // a diameter across and 1.5x deeper along z.
  const Eigen::Vector3d shape(1.0 / 12, 1.0 / 12, 1.5 / 12);
  const std::vector<double> mu{0.05, 0.1, 0.2, 0.4, 0.8};
  Random r(9);
  const double truth = 0.2, sigma = 0.05;
  CycleObservables experiment = synthetic_run(truth, 400, 5, 1.0, r);
  add_noise(experiment, shape, sigma, r);
  FrictionFitOptions o;
  o.noise = NoiseModel::fitted;
  o.noise_shape = shape;
  const FrictionFit fit = fit_friction(experiment, series(mu, 0.0, r), o);
  EXPECT_NEAR(fit.noise_sigma, sigma, 0.015);
  EXPECT_NEAR(std::log(fit.mu_s / truth), 0.0, 0.3);
  EXPECT_LE(fit.mu_s_ci95[0], truth);
  EXPECT_GE(fit.mu_s_ci95[1], truth);
  // Ignored, the noise inflates the small displacements, which reads as lower friction.
  const FrictionFit blind = fit_friction(experiment, series(mu, 0.0, r), {});
  EXPECT_LT(blind.mu_s, fit.mu_s);
}

TEST(FrictionFit, RefusesBadInput) {
  Random r(1);
  const CycleObservables e = synthetic_run(0.2, 100, 2, 1.0, r);
  EXPECT_THROW(fit_friction(e, {}, {}), std::exception);                             // no runs
  EXPECT_THROW(fit_friction(e, series({0.1, 0.2}, 0, r), {}), std::exception);       // < degree + 1
  EXPECT_THROW(fit_friction(e, series({0.2, 0.2, 0.2}, 0, r), {}), std::exception);  // same mu
  EXPECT_THROW(fit_friction(CycleObservables{}, series({0.1, 0.2, 0.4}, 0, r), {}),
               std::exception);  // empty experiment
}

}  // namespace
}  // namespace granmem
