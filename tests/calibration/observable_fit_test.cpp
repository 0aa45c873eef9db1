// The friction fit on steady-state observables: on synthetic twins whose packings differ
// by a shared offset and noise the 95 % interval holds the truth at its rate; on the real
// DEM runs of docs/CALIBRATION.md a packing left out is fitted within its interval.
#include "granmem/calibration/observable_fit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/table.hpp"

namespace granmem {
namespace {

// Three observables with trends in ln mu_s like the lid's packing fraction, the wall force
// and the rotation; a packing adds an offset shared across frictions (correlated between
// the first two, as a denser packing pushes less) and each run its own noise.
struct Synthetic {
  std::mt19937_64 random;
  std::normal_distribution<double> normal{0, 1};
  std::vector<double> values(double mu, const std::vector<double>& packing) {
    const double x = std::log(mu);
    return {0.55 - 0.015 * x - 0.002 * x * x + packing[0] + 0.001 * normal(random),
            7.5 + 2.0 * x + packing[1] + 0.15 * normal(random),
            0.016 + 0.003 * x + packing[2] + 0.0006 * normal(random)};
  }
  std::vector<double> packing() {
    const double shared = normal(random);
    return {0.001 * shared, -0.2 * shared + 0.1 * normal(random), 0.0004 * normal(random)};
  }
  // `packings` packings (seeds 1, 2, ...), each run at every one of `frictions`.
  std::vector<ObservableRun> twin(const std::vector<double>& frictions, int packings) {
    std::vector<ObservableRun> runs;
    for (std::uint64_t seed = 1; seed <= std::uint64_t(packings); ++seed) {
      const std::vector<double> p = packing();
      for (double mu : frictions)
        runs.push_back({mu, seed, values(mu, p)});
    }
    return runs;
  }
  // A truth drawn uniformly in ln mu_s between range[0] and range[1].
  double log_uniform(const std::array<double, 2>& range) {
    const double u = std::uniform_real_distribution<>()(random);
    return std::exp(std::log(range[0]) + std::log(range[1] / range[0]) * u);
  }
};

// A design's 95 % intervals over many truths: how often they hold it, how wide they are.
struct DesignTally {
  int held = 0, trials = 0;
  double ln_width = 0;
  void add(const ObservableFit& fit, double truth) {
    ++trials;
    held += fit.mu_s_ci95[0] <= truth && truth <= fit.mu_s_ci95[1];
    ln_width += std::log(fit.mu_s_ci95[1] / fit.mu_s_ci95[0]);
  }
  double coverage() const { return double(held) / trials; }
  double mean_ln_width() const { return ln_width / trials; }
};

TEST(ObservableFit, TheIntervalHoldsTheTruthAtItsRateOnSyntheticTwins) {
  Synthetic s{std::mt19937_64(11)};
  const std::vector<double> frictions{0.05, 0.1, 0.2, 0.3, 0.5};
  DesignTally tally, without_cv_tally;
  ObservableFitOptions without_cv;
  without_cv.cross_validate = false;
  for (int trial = 0; trial < 150; ++trial) {
    const std::vector<ObservableRun> runs = s.twin(frictions, 2);
    const double truth = s.log_uniform({0.07, 0.4});
    const std::vector<double> experiment = s.values(truth, s.packing());
    const ObservableFit fit = fit_friction_to_observables(experiment, runs);
    tally.add(fit, truth);
    without_cv_tally.add(fit_friction_to_observables(experiment, runs, without_cv), truth);
    EXPECT_EQ(fit.simulations, 10u);
  }
  RecordProperty("coverage", std::to_string(tally.coverage()));
  RecordProperty("mean_ln_width", std::to_string(tally.mean_ln_width()));
  // The figures docs/CALIBRATION.md quotes.
  std::printf("coverage %.3f (without the cross-validation %.3f), mean ln width %.3f\n",
              tally.coverage(), without_cv_tally.coverage(), tally.mean_ln_width());
  EXPECT_GE(tally.coverage(), 0.88) << tally.held << " of " << tally.trials;
  EXPECT_LT(tally.mean_ln_width(), 1.0);  // informative: well under a factor e
}

// An experiment measured with errors the twin cannot reproduce (an offset of each
// observable, drawn anew per experiment at three times its packing's noise): given as the
// experiment's systematic errors its interval holds the truth at its rate; given as zero the
// fit is the one without them.
TEST(ObservableFit, AnExperimentsSystematicErrorsAreCarriedIntoItsInterval) {
  Synthetic s{std::mt19937_64(23)};
  const std::vector<double> frictions{0.05, 0.1, 0.2, 0.3, 0.5};
  const std::vector<double> systematic{0.004, 0.6, 0.0025};
  DesignTally carried, ignored;
  for (int trial = 0; trial < 150; ++trial) {
    const std::vector<ObservableRun> runs = s.twin(frictions, 2);
    const double truth = s.log_uniform({0.07, 0.4});
    std::vector<double> experiment = s.values(truth, s.packing());
    for (std::size_t k = 0; k < experiment.size(); ++k)
      experiment[k] += systematic[k] * s.normal(s.random);
    ObservableFitOptions with;
    with.experiment_systematic = systematic;
    const ObservableFit fit = fit_friction_to_observables(experiment, runs, with);
    const ObservableFit plain = fit_friction_to_observables(experiment, runs);
    carried.add(fit, truth);
    ignored.add(plain, truth);
    EXPECT_GT(fit.systematic_sigma, 0);
    EXPECT_LE(fit.systematic_sigma, fit.gls_sigma * (1 + 1e-9));
    if (trial < 10) {
      with.experiment_systematic.assign(3, 0.0);
      const ObservableFit zero = fit_friction_to_observables(experiment, runs, with);
      EXPECT_EQ(zero.mu_s, plain.mu_s);
      EXPECT_EQ(zero.mu_s_ci95, plain.mu_s_ci95);
      EXPECT_EQ(zero.systematic_sigma, 0);
    }
  }
  // Ignored, such offsets mostly show as a misfit, which widens the interval instead.
  std::printf(
      "with the systematic errors carried: coverage %.3f, mean ln width %.3f; "
      "ignored: %.3f, %.3f\n",
      carried.coverage(), carried.mean_ln_width(), ignored.coverage(), ignored.mean_ln_width());
  EXPECT_GE(carried.coverage(), 0.93) << carried.held << " of " << carried.trials;
  EXPECT_GT(carried.coverage(), ignored.coverage());
  ObservableFitOptions mismatched;
  mismatched.experiment_systematic = {0.001};
  const std::vector<ObservableRun> runs{{0.1, 1, {0.58, 7, 0.01}},
                                        {0.2, 1, {0.57, 8, 0.012}},
                                        {0.3, 1, {0.565, 8.5, 0.013}},
                                        {0.5, 1, {0.56, 9, 0.014}}};
  EXPECT_THROW(fit_friction_to_observables({0.57, 8, 0.012}, runs, mismatched), Error);
}

// One observable, no misfit to widen by: the experiment's systematic error s adds to the
// fit's in quadrature, s / |slope| in ln mu_s, and leaves the fit where it was.
TEST(ObservableFit, OneObservablesSystematicErrorAddsInQuadrature) {
  const double slope = 0.02;  // per unit of ln mu_s
  std::vector<ObservableRun> runs;
  int k = 0;
  for (std::uint64_t seed : {1, 2})
    for (double mu : {0.05, 0.1, 0.2, 0.4})
      runs.push_back({mu, seed, {0.6 + slope * std::log(mu) + 0.0004 * ((k++ % 3) - 1)}});
  ObservableFitOptions linear, with;
  linear.degree = with.degree = 1;
  linear.cross_validate = with.cross_validate = false;
  with.experiment_systematic = {0.003};
  const std::vector<double> experiment{0.6 + slope * std::log(0.15)};
  const ObservableFit plain = fit_friction_to_observables(experiment, runs, linear);
  const ObservableFit fit = fit_friction_to_observables(experiment, runs, with);
  EXPECT_NEAR(fit.mu_s, plain.mu_s, 1e-6);
  EXPECT_NEAR(fit.systematic_sigma, 0.003 / slope, 0.003 / slope * 0.02);
  EXPECT_NEAR(fit.gls_sigma * fit.gls_sigma,
              plain.gls_sigma * plain.gls_sigma + fit.systematic_sigma * fit.systematic_sigma,
              1e-3 * fit.gls_sigma * fit.gls_sigma);
}

// Two designs of one cost on the same synthetic twins: `packings` x `first`, then `added`
// new packings at that fit where it is inside their range (calibrate --refine), against
// `packings` x `fixed`; 150 truths log-uniform in `truths`.
struct TwoDesigns {
  std::vector<double> first;
  int added;
  std::vector<double> fixed;
  int packings;
  std::array<double, 2> truths;
};
std::array<DesignTally, 2> staged_against_fixed(Synthetic& s, const TwoDesigns& d) {
  std::array<DesignTally, 2> tally;
  for (int trial = 0; trial < 150; ++trial) {
    std::vector<ObservableRun> staged, fixed;
    for (std::uint64_t seed = 1; seed <= std::uint64_t(d.packings); ++seed) {
      const std::vector<double> packing = s.packing();
      for (double mu : d.first)
        staged.push_back({mu, seed, s.values(mu, packing)});
      const std::vector<double> other = s.packing();
      for (double mu : d.fixed)
        fixed.push_back({mu, seed + 10, s.values(mu, other)});
    }
    const double truth = s.log_uniform(d.truths);
    const std::vector<double> experiment = s.values(truth, s.packing());
    const double at = fit_friction_to_observables(experiment, staged).mu_s;
    if (at > d.first.front() && at < d.first.back()) {
      for (int k = 1; k <= d.added; ++k)
        staged.push_back({at, std::uint64_t(d.packings + k), s.values(at, s.packing())});
    }
    tally[0].add(fit_friction_to_observables(experiment, staged), truth);
    tally[1].add(fit_friction_to_observables(experiment, fixed), truth);
  }
  std::printf("staged: coverage %.3f, mean ln width %.3f; fixed: coverage %.3f, %.3f\n",
              tally[0].coverage(), tally[0].mean_ln_width(), tally[1].coverage(),
              tally[1].mean_ln_width());
  return tally;
}

// calibrate --refine's design on the same synthetic twins: 3 packings x 3 frictions, then
// 3 new packings at that fit, fitted again on all 12, against the 3 x 4 grid of the same
// cost. The refined interval holds the truth at its rate too, and is narrower on average
// (the new packings measure one packing's scatter where the experiment is).
TEST(ObservableFit, ARefinedDesignHoldsTheTruthAtItsRate) {
  Synthetic s{std::mt19937_64(17)};
  const auto [refined, grid] =
      staged_against_fixed(s, {{0.05, 0.14, 0.4}, 3, {0.05, 0.1, 0.2, 0.4}, 3, {0.07, 0.35}});
  EXPECT_GE(refined.coverage(), 0.88) << refined.held << " of " << refined.trials;
  EXPECT_LT(refined.mean_ln_width(), grid.mean_ln_width());
}

// A placed twin's two designs of 12 runs, truths to 0.5: the wide one, 2 packings x six
// frictions 0.05-0.6, and its default, 2 packings x 0.05, 0.13, 0.35, 0.6 and then 4 new
// packings at that fit. Both hold the truth at their rate; the staged interval is the
// narrower (a third of its runs sit where the truth is).
TEST(ObservableFit, APlacedTwinsStagedDesignIsNarrowerThanItsWideOne) {
  Synthetic s{std::mt19937_64(29)};
  const auto [staged, wide] = staged_against_fixed(
      s, {{0.05, 0.13, 0.35, 0.6}, 4, {0.05, 0.08, 0.13, 0.21, 0.35, 0.6}, 2, {0.07, 0.5}});
  EXPECT_GE(staged.coverage(), 0.88) << staged.held << " of " << staged.trials;
  EXPECT_GE(wide.coverage(), 0.88) << wide.held << " of " << wide.trials;
  EXPECT_LT(staged.mean_ln_width(), wide.mean_ln_width());
}

// The structure informs more at high friction: a packing fraction whose slope in ln mu_s
// is 2x steeper at 0.35 than at 0.1, as the DEM's (docs/CALIBRATION.md), with a rotation
// beside it. Truths drawn near 0.1 and near 0.3, the 3 x 4 grid of calibrate's default:
// carried to the experiment's friction by the trend's predicted error, the held-out
// packings' errors give intervals that hold the truth at their rate at both ends and are
// narrower where one packing moves the fit less; pooled wherever the held-out runs are
// (0.1 and 0.2), they are about as wide at both.
TEST(ObservableFit, TheIntervalIsAsWideAsOnePackingMovesTheFitAtItsFriction) {
  std::mt19937_64 random(23);
  std::normal_distribution<double> normal{0, 1};
  auto values = [&](double mu, double packing) {
    const double x = std::log(mu);
    return std::vector<double>{
        0.55 - 0.0142 * x - 0.002 * x * x + packing + 0.0002 * normal(random),
        0.016 + 0.003 * x + 0.0004 * normal(random)};
  };
  auto packing = [&] { return 0.0006 * normal(random); };
  ObservableFitOptions pooled;
  pooled.cross_validation_by_friction = false;
  struct End {
    double lo, hi;
    int held = 0, held_pooled = 0;
    double width = 0, width_pooled = 0, error2 = 0;
  };
  std::vector<End> ends{{0.08, 0.12}, {0.28, 0.35}};
  const int trials = 150;
  for (End& end : ends) {
    for (int trial = 0; trial < trials; ++trial) {
      std::vector<ObservableRun> grid;
      for (std::uint64_t seed : {1, 2, 3}) {
        const double p = packing();
        for (double mu : {0.05, 0.1, 0.2, 0.4})
          grid.push_back({mu, seed, values(mu, p)});
      }
      const double truth =
          std::exp(std::log(end.lo) +
                   std::log(end.hi / end.lo) * std::uniform_real_distribution<>()(random));
      const std::vector<double> experiment = values(truth, packing());
      const ObservableFit fit = fit_friction_to_observables(experiment, grid);
      const ObservableFit plain = fit_friction_to_observables(experiment, grid, pooled);
      end.held += fit.mu_s_ci95[0] <= truth && truth <= fit.mu_s_ci95[1];
      end.held_pooled += plain.mu_s_ci95[0] <= truth && truth <= plain.mu_s_ci95[1];
      end.width += std::log(fit.mu_s_ci95[1] / fit.mu_s_ci95[0]) / trials;
      end.width_pooled += std::log(plain.mu_s_ci95[1] / plain.mu_s_ci95[0]) / trials;
      end.error2 += std::pow(std::log(fit.mu_s / truth), 2) / trials;
    }
    std::printf(
        "truths %.2f-%.2f: RMS error %.3f in ln mu_s; by friction coverage %.3f, mean ln "
        "width %.3f; pooled %.3f, %.3f\n",
        end.lo, end.hi, std::sqrt(end.error2), double(end.held) / trials, end.width,
        double(end.held_pooled) / trials, end.width_pooled);
  }
  for (const End& end : ends)
    EXPECT_GE(double(end.held) / trials, 0.88) << end.lo << "-" << end.hi;
  const End &low = ends[0], &high = ends[1];
  const double error_ratio = std::sqrt(high.error2 / low.error2);
  EXPECT_NEAR(high.width / low.width, error_ratio, 0.2 * error_ratio);
  EXPECT_GT(high.width_pooled / low.width_pooled, high.width / low.width + 0.1);
}

// Window means over cycles 41-60 of the runs in docs/data/friction/per_run.csv (1,500
// grains, 436 Pa, A = 1 %): rotation / d, bulk packing fraction and coordination from
// positions, packing fraction from the lid, wall force at full compression (N).
struct DemRun {
  double mu;
  std::uint64_t seed;
  std::vector<double> values;
};
const std::vector<DemRun> kDemRuns = {
    {0.05, 1, {0.00860899, 0.624011, 7.03868, 0.594227, 3.78195}},
    {0.05, 2, {0.00824997, 0.621255, 6.80999, 0.591677, 3.49115}},
    {0.1, 1, {0.00961908, 0.620488, 6.93531, 0.583462, 5.1988}},
    {0.1, 2, {0.0107892, 0.620165, 6.87843, 0.585635, 4.73173}},
    {0.2, 1, {0.0129084, 0.615324, 6.69724, 0.576276, 6.37223}},
    {0.2, 2, {0.0134513, 0.615235, 6.62663, 0.576264, 6.04276}},
    {0.3, 1, {0.0140207, 0.601216, 6.50962, 0.565818, 7.58724}},
    {0.3, 2, {0.0141037, 0.604235, 6.43488, 0.563245, 7.1794}},
    {0.5, 1, {0.0158644, 0.596833, 6.16725, 0.556519, 8.45497}},
    {0.5, 2, {0.0183237, 0.600304, 6.1847, 0.557426, 8.03147}},
};

// One packing's runs are the twin, the other's at interior frictions the experiments: the
// fit lands within 0.035 of the truth. With one packing in the twin its intervals see only
// the scatter about the trend, not a packing's shared offset (the wall force of seed 1 is
// 0.3-0.5 N higher at every friction): 5 of these 6 hold the truth, one misses by 0.004 —
// the reason the twin needs two packings or more, and the fit cross-validates across them.
TEST(ObservableFit, APackingLeftOutOfRealDemRunsIsFittedWithinPointZeroThreeFive) {
  int held = 0;
  for (std::uint64_t left_out : {1, 2}) {
    std::vector<ObservableRun> twin;
    for (const DemRun& r : kDemRuns)
      if (r.seed != left_out) twin.push_back({r.mu, r.seed, r.values});
    for (const DemRun& r : kDemRuns) {
      if (r.seed != left_out || r.mu == 0.05 || r.mu == 0.5) continue;
      const ObservableFit fit = fit_friction_to_observables(r.values, twin);
      SCOPED_TRACE("seed " + std::to_string(left_out) + " at mu_s " + std::to_string(r.mu));
      std::printf("seed %d left out, mu_s %.1f: fitted %.3f, 95 %% %.3f-%.3f\n", int(left_out),
                  r.mu, fit.mu_s, fit.mu_s_ci95[0], fit.mu_s_ci95[1]);
      EXPECT_NEAR(fit.mu_s, r.mu, 0.035);
      held += fit.mu_s_ci95[0] <= r.mu && r.mu <= fit.mu_s_ci95[1];
    }
  }
  EXPECT_GE(held, 5);
}

// The 34 steady-state fits of docs/CALIBRATION.md, re-made from their window means
// (docs/data/friction/pseudo_experiment_window_means.csv, scripts/collect_window_means.py):
// DEM pseudo-experiments of 1,500-3,000 grains at frictions their twins were not told,
// each twin 12 runs (3 packings x 4 frictions, or 3 x 3 refined by 3 new packings at the
// first fit). The 95 % intervals hold the truth at their rate, and are only as wide as the
// errors the fits make: their half-width is ~1.96 RMS errors in ln mu_s, as for a normal
// error.
struct FitCase {
  double truth = 0;
  std::vector<double> experiment;
  std::vector<ObservableRun> twin;
};

std::vector<FitCase> dem_fit_cases() {
  const std::vector<std::string> observables{"rot_disp",
                                             "bulk_packing_fraction",
                                             "coordination",
                                             "height_packing_fraction",
                                             "wall_force_full_compression",
                                             "wall_force_unloaded"};
  std::vector<std::string> columns{"case", "role", "mu_s_true", "mu_s", "seed"};
  columns.insert(columns.end(), observables.begin(), observables.end());
  const Table t =
      read_csv(GRANMEM_DOCS_DATA "/friction/pseudo_experiment_window_means.csv", columns).table;
  std::vector<FitCase> cases;
  for (std::size_t row = 0; row < t.rows(); ++row) {
    const auto c = std::size_t(t["case"].values[row]);
    if (cases.size() <= c) cases.resize(c + 1);
    FitCase& fit_case = cases[c];
    std::vector<double> values;
    for (const std::string& name : observables) {
      const double v = t[name].values[row];
      if (!std::isnan(v)) values.push_back(v);
    }
    if (t["role"].values[row] == 0) {
      fit_case.truth = t["mu_s_true"].values[row];
      fit_case.experiment = values;
    } else {
      fit_case.twin.push_back(
          {t["mu_s"].values[row], std::uint64_t(t["seed"].values[row]), values});
    }
  }
  return cases;
}

TEST(ObservableFit, DemPseudoExperimentsAreHeldAtTheIntervalsRate) {
  const std::vector<FitCase> cases = dem_fit_cases();
  ASSERT_EQ(cases.size(), 34u);
  int held = 0, held_without_cv = 0;
  double error2 = 0, half_width = 0;
  ObservableFitOptions without_cv, pooled;
  without_cv.cross_validate = false;
  pooled.cross_validation_by_friction = false;
  // Each fit, for docs/data/friction/cross_validation_by_friction.csv.
  std::printf("case,mu_s_true,mu_s,ci95_low,ci95_high,pooled_ci95_low,pooled_ci95_high\n");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const FitCase& c = cases[i];
    ASSERT_EQ(c.twin.size(), 12u);
    const ObservableFit fit = fit_friction_to_observables(c.experiment, c.twin);
    const ObservableFit plain = fit_friction_to_observables(c.experiment, c.twin, without_cv);
    const ObservableFit pooled_fit = fit_friction_to_observables(c.experiment, c.twin, pooled);
    std::printf("%zu,%g,%.4f,%.4f,%.4f,%.4f,%.4f\n", i, c.truth, fit.mu_s, fit.mu_s_ci95[0],
                fit.mu_s_ci95[1], pooled_fit.mu_s_ci95[0], pooled_fit.mu_s_ci95[1]);
    held += fit.mu_s_ci95[0] <= c.truth && c.truth <= fit.mu_s_ci95[1];
    held_without_cv += plain.mu_s_ci95[0] <= c.truth && c.truth <= plain.mu_s_ci95[1];
    error2 += std::pow(std::log(fit.mu_s / c.truth), 2);
    half_width += std::log(fit.mu_s_ci95[1] / fit.mu_s_ci95[0]) / 2;
  }
  const double n = double(cases.size());
  const double rms_error = std::sqrt(error2 / n);
  half_width /= n;
  std::printf(
      "DEM pseudo-experiments: %d of %zu held (without the cross-validation %d); "
      "RMS error %.3f and mean half-width %.3f in ln mu_s\n",
      held, cases.size(), held_without_cv, rms_error, half_width);
  // At a 95 % rate, 30 or more of 34 hold with probability 0.974 (binomial); the two fits
  // of one pseudo-experiment share its packing, so this is looser than it reads.
  EXPECT_GE(held, 30);
  // Honest both ways: narrower than 1.5 RMS errors the intervals would hold ~87 %,
  // wider than 3 they would say less than the fits know.
  EXPECT_GT(half_width / rms_error, 1.5);
  EXPECT_LT(half_width / rms_error, 3.0);
  EXPECT_LT(rms_error, 0.1);  // and the fits informative: +-10 % in mu_s
}

const std::vector<std::string> kNames{"rot_disp", "bulk_packing_fraction", "coordination",
                                      "packing_fraction", "wall_force_full_compression"};

SteadyState steady(const std::vector<double>& values, std::size_t count) {
  SteadyState s;
  s.names.assign(kNames.begin(), kNames.begin() + std::ptrdiff_t(count));
  s.values.assign(values.begin(), values.begin() + std::ptrdiff_t(count));
  return s;
}

// A scan has no lid height nor wall force: the fit by name uses what the experiment and
// every run have, gives the same answer as the fit on those columns, and its trend curve
// spans the runs' frictions through the model at the fit.
TEST(ObservableFit, ByNameTheFitUsesWhatTheExperimentAndEveryRunHave) {
  std::vector<SteadyStateRun> twin;
  std::vector<ObservableRun> columns;
  for (const DemRun& r : kDemRuns) {
    if (r.seed == 2 && r.mu == 0.2) continue;
    twin.push_back({r.mu, r.seed, steady(r.values, 5)});
    columns.push_back({r.mu, r.seed, {r.values.begin(), r.values.begin() + 3}});
  }
  const DemRun& experiment = kDemRuns[5];  // seed 2 at 0.2, as a scan: positions only
  const ObservableFit fit = fit_friction_to_steady_state(steady(experiment.values, 3), twin);
  ASSERT_EQ(fit.names, std::vector<std::string>(kNames.begin(), kNames.begin() + 3));
  const ObservableFit same = fit_friction_to_observables(
      {experiment.values.begin(), experiment.values.begin() + 3}, columns);
  EXPECT_DOUBLE_EQ(fit.mu_s, same.mu_s);
  ASSERT_EQ(fit.curve.size(), 3u);
  EXPECT_NEAR(fit.curve_mu_s.front(), 0.05, 1e-12);
  EXPECT_NEAR(fit.curve_mu_s.back(), 0.5, 1e-12);
  // The curve is the trend: between its samples it brackets the model at the fit.
  const auto k =
      std::size_t(std::lower_bound(fit.curve_mu_s.begin(), fit.curve_mu_s.end(), fit.mu_s) -
                  fit.curve_mu_s.begin());
  ASSERT_GT(k, 0u);
  for (std::size_t o = 0; o < 3; ++o) {
    const double lo = std::min(fit.curve[o][k - 1], fit.curve[o][k]);
    const double hi = std::max(fit.curve[o][k - 1], fit.curve[o][k]);
    EXPECT_GE(fit.model[o], lo - 1e-12);
    EXPECT_LE(fit.model[o], hi + 1e-12);
  }
  // Asked for by name, an observable the scan lacks is an error, not silently dropped.
  EXPECT_THROW(fit_friction_to_steady_state(steady(experiment.values, 3), twin, {},
                                            {"rot_disp", "wall_force_full_compression"}),
               Error);
  const ObservableFit two = fit_friction_to_steady_state(steady(experiment.values, 5), twin, {},
                                                         {"packing_fraction", "rot_disp"});
  EXPECT_EQ(two.names, (std::vector<std::string>{"packing_fraction", "rot_disp"}));
  // The experiment's systematic errors travel with it, by name.
  SteadyState measured = steady(experiment.values, 3);
  measured.systematic = {0.0, 0.0, 0.002};
  // The default options, with the same errors by position.
  const ObservableFitOptions same_errors{2, true, true, measured.systematic};
  const ObservableFit carried = fit_friction_to_steady_state(measured, twin);
  EXPECT_GT(carried.systematic_sigma, 0);
  EXPECT_DOUBLE_EQ(carried.mu_s, fit_friction_to_observables(
                                     {experiment.values.begin(), experiment.values.begin() + 3},
                                     columns, same_errors)
                                     .mu_s);
}

// Four observables that move with both frictions, as in the DEM: packing fraction and
// wall force with mu_s mostly, the rotation against mu_r (rolling friction resists it),
// coordination with both; a packing's offset shared across the runs of its seed.
struct SyntheticJoint {
  std::mt19937_64 random;
  std::normal_distribution<double> normal{0, 1};
  std::vector<double> values(double mu_s, double mu_r, const std::vector<double>& packing) {
    const double x = std::log(mu_s), y = std::log(mu_r);
    return {0.55 - 0.015 * x - 0.004 * y + packing[0] + 0.001 * normal(random),
            7.5 + 2.0 * x + 0.4 * y + packing[1] + 0.15 * normal(random),
            0.016 + 0.003 * x - 0.006 * y - 0.0005 * y * y + packing[2] + 0.0006 * normal(random),
            6.7 - 0.25 * x - 0.2 * y + packing[3] + 0.03 * normal(random)};
  }
  std::vector<double> packing() {
    const double shared = normal(random);
    return {0.001 * shared, -0.2 * shared + 0.1 * normal(random), 0.0004 * normal(random),
            0.04 * normal(random)};
  }
};

bool inside(const std::vector<std::array<double, 2>>& polygon, double x, double y) {
  bool in = false;  // ray casting, in the logs where the region is an ellipse
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const double xi = std::log(polygon[i][0]), yi = std::log(polygon[i][1]);
    const double xj = std::log(polygon[j][0]), yj = std::log(polygon[j][1]);
    if ((yi > std::log(y)) != (yj > std::log(y)) &&
        std::log(x) < (xj - xi) * (std::log(y) - yi) / (yj - yi) + xi) {
      in = !in;
    }
  }
  return in;
}

// The joint fit on a 3 x 3 design per packing, 2 packings: both marginal intervals and the
// joint region hold the truth at their rate, and the fit finds both frictions.
TEST(ObservableFit, TheJointFitOfMuSAndMuRHoldsBothAtTheirRate) {
  SyntheticJoint s{std::mt19937_64(5)};
  int held_s = 0, held_r = 0, held_region = 0, trials = 0;
  double error_s = 0, error_r = 0;
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<ObservableRun> runs;
    for (std::uint64_t seed : {1, 2}) {
      const std::vector<double> packing = s.packing();
      for (double mu_s : {0.05, 0.12, 0.3})
        for (double mu_r : {0.004, 0.012, 0.036})
          runs.push_back({mu_s, seed, s.values(mu_s, mu_r, packing), mu_r});
    }
    std::uniform_real_distribution<> u;
    const double true_s = std::exp(std::log(0.06) + std::log(0.25 / 0.06) * u(s.random));
    const double true_r = std::exp(std::log(0.005) + std::log(0.03 / 0.005) * u(s.random));
    const JointObservableFit fit =
        fit_frictions_to_observables(s.values(true_s, true_r, s.packing()), runs);
    ++trials;
    held_s += fit.mu_s_ci95[0] <= true_s && true_s <= fit.mu_s_ci95[1];
    held_r += fit.mu_r_ci95[0] <= true_r && true_r <= fit.mu_r_ci95[1];
    held_region += inside(fit.region95, true_s, true_r);
    error_s += std::pow(std::log(fit.mu_s / true_s), 2) / 100;
    error_r += std::pow(std::log(fit.mu_r / true_r), 2) / 100;
    EXPECT_EQ(fit.simulations, 18u);
    EXPECT_LE(std::abs(fit.correlation), 1.0);
  }
  std::printf("joint: coverage mu_s %.2f, mu_r %.2f, region %.2f; RMS ln error %.3f, %.3f\n",
              double(held_s) / trials, double(held_r) / trials, double(held_region) / trials,
              std::sqrt(error_s), std::sqrt(error_r));
  EXPECT_GE(held_s, 88);
  EXPECT_GE(held_r, 88);
  EXPECT_GE(held_region, 88);
  // Both identified: well inside the truths' spread (RMS 0.41 and 0.52 in ln about the
  // middle of their ranges).
  EXPECT_LT(std::sqrt(error_s), 0.25);
  EXPECT_LT(std::sqrt(error_r), 0.35);
}

// One cycle ahead: each segment (a cycle the twin is placed into anew) moves the
// experiment and the twin's runs alike by that cycle's own state, each run by its own noise
// and the experiment by its one-cycle chaos, twice the runs' noise (what the twin's jittered
// replicas do not see). Observables like the wall force, the lid's packing fraction and the
// rotation, their one-cycle noise ~0.01 in ln mu_s each.
struct SyntheticSegments {
  std::mt19937_64 random;
  double noise_scale = 1;  // the runs' and the experiment's noise, as a multiple of the model's
  std::normal_distribution<double> normal{0, 1};
  std::vector<double> values(double mu, const std::vector<double>& cycle, double noise) {
    const double x = std::log(mu);
    return {0.55 - 0.015 * x - 0.002 * x * x + cycle[0] + noise * 1.5e-4 * normal(random),
            7.5 + 2.0 * x + cycle[1] + noise * 0.02 * normal(random),
            0.016 + 0.003 * x + cycle[2] + noise * 3e-5 * normal(random)};
  }
  static SteadyState state(std::vector<double> v) {
    SteadyState st;
    st.names = {"a", "b", "c"};
    st.values = std::move(v);
    return st;
  }
  // Four runs about a first fit off the truth by ~5 %, at the design's / 1.2 ... x 1.2.
  std::vector<SteadyStateSegment> draw(double truth, int segments) {
    const double centre = truth * std::exp(0.05 * normal(random));
    std::vector<SteadyStateSegment> out;
    for (int c = 0; c < segments; ++c) {
      const std::vector<double> cycle{0.002 * normal(random), 0.3 * normal(random),
                                      0.0005 * normal(random)};
      SteadyStateSegment seg;
      seg.experiment = state(values(truth, cycle, 2.0 * noise_scale));
      std::uint64_t seed = 3;
      for (double f : {1 / 1.2, 1 / 1.07, 1.07, 1.2})
        seg.runs.push_back({centre * f, seed++, state(values(centre * f, cycle, noise_scale))});
      out.push_back(std::move(seg));
    }
    return out;
  }
  double log_uniform(double lo, double hi) {
    return std::exp(std::log(lo) + std::log(hi / lo) * std::uniform_real_distribution<>()(random));
  }
};

TEST(ObservableFit, OneCycleAheadSegmentsHoldTheTruthAtTheirRate) {
  SyntheticSegments g{std::mt19937_64(42)};
  int held = 0;
  double error2 = 0;
  const int trials = 400;
  for (int trial = 0; trial < trials; ++trial) {
    const double truth = g.log_uniform(0.1, 0.5);
    const SegmentedFit fit = fit_friction_by_segments(g.draw(truth, 10));
    held += fit.mu_s_ci95[0] <= truth && truth <= fit.mu_s_ci95[1];
    error2 += std::pow(std::log(fit.mu_s / truth) / fit.log_mu_s_sigma, 2);
    ASSERT_EQ(fit.segment_mu_s.size(), 10u);
    ASSERT_EQ(fit.runs, 4u);
  }
  const double z_rms = std::sqrt(error2 / trials);
  std::printf("one cycle ahead: coverage %.3f, error over sigma RMS %.2f\n", double(held) / trials,
              z_rms);
  EXPECT_GE(held, int(0.90 * trials));
  EXPECT_LE(held, int(0.99 * trials));
  // The error is what the sigma says (Student's t for 9 dof makes the mean's z RMS ~1.13).
  EXPECT_GT(z_rms, 0.8);
  EXPECT_LT(z_rms, 1.4);
}

TEST(ObservableFit, OneCycleAheadOffsetsCrossZeroAtTheTruth) {
  // Nearly noiseless segments: every run less its cycle's experiment is the model's change
  // from the truth, the same in every cycle whatever the cycle's own offset, so the cycles'
  // mean trend of it crosses 0 at the truth for each observable.
  SyntheticSegments g{std::mt19937_64(11), 1e-3};
  const std::vector<SteadyStateSegment> segments = g.draw(0.25, 5);
  const SegmentedFit fit = fit_friction_by_segments(segments);
  ASSERT_EQ(fit.run_mu_s.size(), 5u * 4u);
  ASSERT_EQ(fit.offset.size(), 3u);
  EXPECT_DOUBLE_EQ(fit.offset[1][6],
                   segments[1].runs[2].state.values[1] - segments[1].experiment.values[1]);
  EXPECT_NEAR(fit.mu_s, 0.25, 0.25 * 1e-3);
  ASSERT_EQ(fit.segment_log_sigma.size(), 5u);
  for (double sigma : fit.segment_log_sigma)
    EXPECT_LT(sigma, 1e-3);
  for (std::size_t o = 0; o < 3; ++o) {
    const std::vector<double>& y = fit.curve_offset[o];
    const double span = std::abs(y.back() - y.front());
    std::size_t k = 0;
    while (k + 1 < y.size() && fit.curve_mu_s[k + 1] < 0.25)
      ++k;
    const double w =
        std::log(0.25 / fit.curve_mu_s[k]) / std::log(fit.curve_mu_s[k + 1] / fit.curve_mu_s[k]);
    EXPECT_LT(std::abs(y[k] + w * (y[k + 1] - y[k])), 1e-2 * span) << fit.names[o];
    EXPECT_GT(fit.offset_error[o], 0);
  }
}

TEST(ObservableFit, OneCycleAheadNeedsThreeSegmentsAndTheSameObservables) {
  SyntheticSegments g{std::mt19937_64(5)};
  std::vector<SteadyStateSegment> segments = g.draw(0.3, 2);
  EXPECT_THROW(fit_friction_by_segments(segments), Error);
  segments = g.draw(0.3, 4);
  // An observable one segment lacks is left out of every segment's fit.
  segments[1].experiment.values[2] = std::nan("");
  const SegmentedFit fit = fit_friction_by_segments(segments);
  EXPECT_EQ(fit.names, (std::vector<std::string>{"a", "b"}));
  EXPECT_THROW(fit_friction_by_segments(segments, {}, {"c"}), Error);
}

TEST(ObservableFit, TooFewRunsOrMismatchedObservablesAreRefused) {
  const std::vector<ObservableRun> three{{0.1, 1, {1, 2}}, {0.2, 1, {2, 3}}, {0.3, 1, {3, 4}}};
  EXPECT_THROW(fit_friction_to_observables({1.5, 2.5}, three), Error);
  std::vector<ObservableRun> four = three;
  four.push_back({0.4, 1, {4}});
  EXPECT_THROW(fit_friction_to_observables({1.5, 2.5}, four), Error);
}

}  // namespace
}  // namespace granmem
