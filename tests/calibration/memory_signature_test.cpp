// The memory signature's numbers recover what synthetic read-out curves were built with:
// a dip of known depth, a trained/untrained ratio, and the exponents of a broken power law.
#include "granmem/calibration/memory_signature.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

constexpr double kA = 0.01;  // training amplitude, fraction of the box

// The paper's sweep, 0.05 % to 2.5 % in 12 log-spaced steps, with A added.
std::vector<double> sweep() {
  std::vector<double> a;
  for (int k = 0; k < 12; ++k)
    a.push_back(0.0005 * std::pow(50.0, k / 11.0));
  a.push_back(kA);
  std::sort(a.begin(), a.end());
  return a;
}

// value = 0.02 (A'/A)^below up to A, 0.02 (A'/A)^above beyond; errors 1 % of the values.
ReadoutCurve broken_power_law(double below, double above) {
  ReadoutCurve c;
  c.amplitude = sweep();
  for (double a : c.amplitude) {
    c.value.push_back(0.02 * std::pow(a / kA, a <= kA ? below : above));
    c.error.push_back(0.01 * c.value.back());
  }
  return c;
}

std::size_t at_training(const ReadoutCurve& c) {
  return std::size_t(std::find(c.amplitude.begin(), c.amplitude.end(), kA) - c.amplitude.begin());
}

TEST(MemorySignature, TheExponentsOfABrokenPowerLawAreRecovered) {
  const ReadoutExponents e = readout_exponents(broken_power_law(0.7, 1.4), kA);
  ASSERT_TRUE(e.below.converged);
  ASSERT_TRUE(e.above.converged);
  EXPECT_EQ(e.below.points, 10u);  // 0.05 % ... 0.86 % (nine), and A
  EXPECT_EQ(e.above.points, 4u);   // A, 1.22 %, 1.75 %, 2.5 %
  EXPECT_NEAR(e.below.exponent, 0.7, 1e-6);
  EXPECT_NEAR(e.above.exponent, 1.4, 1e-6);
  EXPECT_LE(e.above.exponent_ci95[0], 1.4);
  EXPECT_GE(e.above.exponent_ci95[1], 1.4);
}

TEST(MemorySignature, ADipIsItsDepthBelowTheNeighboursPowerLaw) {
  ReadoutCurve c = broken_power_law(1.0, 1.0);  // one power law: no dip
  EXPECT_NEAR(interpolation_dip(c, kA).depth, 0, 1e-12);
  const std::size_t k = at_training(c);
  c.value[k] *= 0.6;
  c.error[k] *= 0.6;
  const MemoryDip d = interpolation_dip(c, kA);
  EXPECT_NEAR(d.depth, 0.4, 1e-12);
  EXPECT_NEAR(d.interpolated, 0.02, 1e-12);
  // Errors: 1 % at each point; A sits at t of the way between its neighbours in log A'.
  const double t =
      std::log(kA / c.amplitude[k - 1]) / std::log(c.amplitude[k + 1] / c.amplitude[k - 1]);
  const double interp = 0.01 * std::hypot(1 - t, t);
  EXPECT_NEAR(d.interpolated_error, 0.02 * interp, 1e-15);
  EXPECT_NEAR(d.depth_error, 0.6 * std::hypot(0.01, interp), 1e-12);
}

TEST(MemorySignature, TrainedOverUntrainedAtTheTrainingAmplitude) {
  const ReadoutCurve untrained = broken_power_law(1.0, 1.0);
  ReadoutCurve trained = untrained;
  trained.value[at_training(trained)] *= 0.5;
  const TrainedRatio r = trained_ratio(trained, untrained, kA);
  EXPECT_NEAR(r.ratio, 0.5, 1e-12);
  EXPECT_NEAR(r.error, 0.5 * std::hypot(0.02, 0.01), 1e-12);  // trained error kept at 0.01 v
}

TEST(MemorySignature, ATrainingAmplitudeOutsideTheSweepIsRefused) {
  const ReadoutCurve c = broken_power_law(0.7, 1.4);
  EXPECT_THROW(interpolation_dip(c, 0.011), Error);
  EXPECT_THROW(interpolation_dip(c, c.amplitude.back()), Error);  // no neighbour above
  EXPECT_THROW(readout_exponents(c, 0.011), Error);
}

}  // namespace
}  // namespace granmem
