#include "granmem/calibration/distribution_distance.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/random.hpp"

namespace granmem {
namespace {

TEST(DistributionDistance, HandComputedSmallSamples) {
  // F_a - F_b: 1/3 on [1,2), 1/6 on [2,3), 1/2 on [3,4), 0 after.
  const std::vector<double> a{3, 1, 2}, b{4, 2};
  EXPECT_DOUBLE_EQ(ks_distance(a, b), 0.5);
  EXPECT_DOUBLE_EQ(wasserstein1_distance(a, b), 1.0 / 3 + 1.0 / 6 + 1.0 / 2);
  EXPECT_DOUBLE_EQ(ks_distance(b, a), 0.5);
  EXPECT_DOUBLE_EQ(wasserstein1_distance(b, a), 1.0);
}

TEST(DistributionDistance, TiesAndNaNs) {
  // NaN dropped; tied values step the CDFs together: F_a = 1/2, F_b = 1/3 after 1.
  const std::vector<double> a{1, 1, 2, 2, std::nan("")}, b{1, 5, 5};
  EXPECT_DOUBLE_EQ(ks_distance(a, b), 2.0 / 3);
  // |F_a - F_b|: 1/6 on [1,2), 2/3 on [2,5).
  EXPECT_DOUBLE_EQ(wasserstein1_distance(a, b), 1.0 / 6 + 3 * 2.0 / 3);
  EXPECT_THROW(ks_distance({}, b), std::exception);
}

TEST(DistributionDistance, ShiftedSampleIsItsShiftAway) {
  Random r(3);
  std::vector<double> a, b;
  for (int i = 0; i < 1000; ++i) {
    a.push_back(r.normal());
    b.push_back(a.back() + 0.25);
  }
  EXPECT_NEAR(wasserstein1_distance(a, b), 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(ks_distance(a, a), 0.0);
  EXPECT_DOUBLE_EQ(wasserstein1_distance(a, a), 0.0);
}

TEST(DistributionDistance, KsPValueOfTheSameDistribution) {
  // Two samples of one distribution: the p-value is uniform, so rarely tiny; of a shifted
  // one, tiny. Kolmogorov's Q at lambda = 1.36 is 0.049.
  EXPECT_NEAR(ks_p_value(1.36 / std::sqrt(5000.0), 10000, 10000), 0.049, 0.002);
  Random r(5);
  std::vector<double> a, b, c;
  for (int i = 0; i < 2000; ++i) {
    a.push_back(r.normal());
    b.push_back(r.normal());
    c.push_back(r.normal() + 0.3);
  }
  EXPECT_GT(ks_p_value(ks_distance(a, b), a.size(), b.size()), 0.01);
  EXPECT_LT(ks_p_value(ks_distance(a, c), a.size(), c.size()), 1e-6);
}

}  // namespace
}  // namespace granmem
