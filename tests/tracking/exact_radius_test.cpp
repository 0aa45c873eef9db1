#include "exact_radius.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace granmem {
namespace {

// A sample of grains as locate sees them (um): each model fit's radius runs small by the
// blur's curvature shift and scatters by its noise, each exact refit's by much less.
struct RadiusSample {
  std::vector<double> truth, model, exact;
};

RadiusSample radius_sample(std::size_t n, double polydispersity, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> size(1 - polydispersity, 1 + polydispersity);
  std::normal_distribution<double> model_noise(0, 13), exact_noise(0, 3);
  RadiusSample s;
  for (std::size_t k = 0; k < n; ++k) {
    s.truth.push_back(2500 * size(random));
    s.model.push_back(s.truth.back() - 146 + model_noise(random));
    s.exact.push_back(s.truth.back() + exact_noise(random));
  }
  return s;
}

double median_difference(const RadiusSample& s) {
  std::vector<double> d;
  for (std::size_t k = 0; k < s.model.size(); ++k)
    d.push_back(s.exact[k] - s.model[k]);
  std::nth_element(d.begin(), d.begin() + long(d.size() / 2), d.end());
  return d[d.size() / 2];
}

// RMS error against the truth of the radii drawn for a packing's grains (not the sample's).
template <class Draw>
double rms_error(const RadiusSample& packing, Draw draw) {
  double sum = 0;
  for (std::size_t k = 0; k < packing.model.size(); ++k)
    sum += std::pow(draw(packing.model[k]) - packing.truth[k], 2);
  return std::sqrt(sum / double(packing.model.size()));
}

constexpr int kTrials = 200;

// kTrials samples of 24 grains, each with a packing of 3,000 alike and the sample's line.
template <class Trial>
void for_each_trial(double polydispersity, unsigned seed, const Trial& trial) {
  for (unsigned t = 0; t < unsigned(kTrials); ++t) {
    const RadiusSample sample = radius_sample(24, polydispersity, seed + t);
    const RadiusSample packing = radius_sample(3000, polydispersity, seed + 5000 + t);
    trial(sample, packing, fit_exact_radius(sample.model, sample.exact));
  }
}

TEST(ExactRadius, AlikeGrainsAreDrawnAtTheSamplesExactRadiusWithoutTheModelFitsNoise) {
  // Monodisperse: the model radii scatter by noise alone, the slope ~0, and every grain
  // drawn at the sample's mean exact radius: within the exact refits' 3 um / sqrt(24),
  // where the model fit plus the median shortfall carries each grain's 13 um of noise
  // and the sample median's ~3 um.
  double line_sum = 0, shortfall_sum = 0;
  for_each_trial(
      0, 100,
      [&](const RadiusSample& sample, const RadiusSample& packing, const ExactRadius& line) {
        EXPECT_LT(line.slope, 0.4);
        const double shortfall = median_difference(sample);
        line_sum += std::pow(rms_error(packing, line), 2);
        shortfall_sum += std::pow(rms_error(packing, [&](double r) { return r + shortfall; }), 2);
      });
  const double line_rms = std::sqrt(line_sum / kTrials);
  const double shortfall_rms = std::sqrt(shortfall_sum / kTrials);
  EXPECT_LT(line_rms, 3.5);        // ~1: the sample's mean (3 / sqrt 24), b ~0.05 of 13
  EXPECT_GT(shortfall_rms, 12.5);  // the model fit's 13 um
}

TEST(ExactRadius, GrainsOfDifferentSizesKeepThemAndLoseTheShortfall) {
  // 5 % polydispersity (72 um SD) over 13 um of noise: slope ~0.97 (the best linear
  // predictor shrinks the model's noise), each grain drawn at its own size, and the
  // packing's mean radius unbiased.
  double bias_sum = 0;
  for_each_trial(
      0.05, 300, [&](const RadiusSample&, const RadiusSample& packing, const ExactRadius& line) {
        EXPECT_GT(line.slope, 0.85);
        EXPECT_LE(line.slope, 1.0);
        EXPECT_LT(rms_error(packing, line), 16);  // the model's 13 um, not the 72 um spread
        double bias = 0;
        for (std::size_t k = 0; k < packing.model.size(); ++k)
          bias += (line(packing.model[k]) - packing.truth[k]) / double(packing.model.size());
        bias_sum += bias;
      });
  EXPECT_NEAR(bias_sum / kTrials, 0, 0.5);
}

TEST(ExactRadius, FewOrAlikeOrMissingPairs) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ExactRadius none = fit_exact_radius({}, {});
  EXPECT_DOUBLE_EQ(none(2350), 2350);  // the model fit's radius as it is
  const ExactRadius one = fit_exact_radius({2350, nan}, {2496, 2400});
  EXPECT_DOUBLE_EQ(one.slope, 1);
  EXPECT_DOUBLE_EQ(one(2300), 2446);  // the one pair's difference
  const ExactRadius alike = fit_exact_radius({2350, 2350}, {2490, 2500});
  EXPECT_DOUBLE_EQ(alike(2350), 2495);
  // Exact radii falling as the model's rise: not a grain's size; the slope held at 0.
  const ExactRadius falling = fit_exact_radius({2340, 2360}, {2500, 2490});
  EXPECT_DOUBLE_EQ(falling.slope, 0);
  EXPECT_DOUBLE_EQ(falling(2000), 2495);
}

}  // namespace
}  // namespace granmem
