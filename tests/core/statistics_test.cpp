#include "granmem/core/statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/error.hpp"

#include "checks.hpp"

namespace granmem {
namespace {

using testing::pdf_integral;
using testing::pdf_total_count;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Summarize, OddCount) {
  const Summary s = summarize({3, 1, 2});
  EXPECT_EQ(s.count, 3u);
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_EQ(s.median, 2.0);
  EXPECT_DOUBLE_EQ(s.mean_square, 14.0 / 3.0);
}

TEST(Summarize, EvenCountMedianIsTheMeanOfTheMiddleTwo) {
  const Summary s = summarize({4, 1, 3, 2});
  EXPECT_EQ(s.count, 4u);
  EXPECT_EQ(s.mean, 2.5);
  EXPECT_EQ(s.median, 2.5);
  EXPECT_EQ(s.mean_square, 7.5);
  EXPECT_EQ(summarize({10, -1, 7, 3, 8, 2}).median, 5.0);  // sorted: -1 2 3 7 8 10
  EXPECT_EQ(summarize({5, 5, 1, 9}).median, 5.0);
  EXPECT_EQ(summarize({-2, 6}).median, 2.0);
}

TEST(Summarize, NanAndInfinitiesAreNotMeasured) {
  const Summary s = summarize({kNaN, 5, 1, kNaN, kInf, -kInf});
  EXPECT_EQ(s.count, 2u);
  EXPECT_EQ(s.mean, 3.0);
  EXPECT_EQ(s.median, 3.0);
  EXPECT_EQ(s.mean_square, 13.0);
}

TEST(Summarize, EmptyGivesNan) {
  for (const std::vector<double>& v : {std::vector<double>{}, std::vector<double>{kNaN, kNaN}}) {
    const Summary s = summarize(v);
    EXPECT_EQ(s.count, 0u);
    EXPECT_TRUE(std::isnan(s.mean));
    EXPECT_TRUE(std::isnan(s.median));
    EXPECT_TRUE(std::isnan(s.mean_square));
  }
  const Summary one = summarize({-4});
  EXPECT_EQ(one.count, 1u);
  EXPECT_EQ(one.mean, -4.0);
  EXPECT_EQ(one.median, -4.0);
  EXPECT_EQ(one.mean_square, 16.0);
}

TEST(Summarize, MatchesADirectComputation) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(2, 3);
  std::vector<double> v(1001);
  for (double& x : v)
    x = g(rng);
  double sum = 0, sq = 0;
  for (double x : v) {
    sum += x;
    sq += x * x;
  }
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  const Summary s = summarize(v);
  EXPECT_DOUBLE_EQ(s.mean, sum / 1001);
  EXPECT_DOUBLE_EQ(s.mean_square, sq / 1001);
  EXPECT_EQ(s.median, sorted[500]);
  v.pop_back();
  sorted = v;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(summarize(v).median, 0.5 * (sorted[499] + sorted[500]));
}

TEST(ProbabilityDensity, LinearBinsKnownCounts) {
  // 0..8 in 4 bins of width 2 over the default range [0, 8]; the maximum goes in the last bin.
  std::vector<double> v = {8, 0, 1, 2, 3, 4, 5, 6, 7, kNaN};
  DensityOptions o;
  o.bins = 4;
  const Table t = probability_density(v, o, "mm");
  ASSERT_EQ(t.rows(), 4u);
  ASSERT_EQ(t.columns().size(), 5u);
  EXPECT_EQ(t.columns()[0].name, "bin_lo");
  EXPECT_EQ(t.columns()[1].name, "bin_hi");
  EXPECT_EQ(t.columns()[2].name, "bin_center");
  EXPECT_EQ(t.columns()[3].name, "count");
  EXPECT_EQ(t.columns()[4].name, "density");
  EXPECT_EQ(t["bin_lo"].unit, "mm");
  EXPECT_EQ(t["density"].unit, "1/mm");
  EXPECT_TRUE(t["count"].integer);
  EXPECT_EQ(t["bin_lo"].values, (std::vector<double>{0, 2, 4, 6}));
  EXPECT_EQ(t["bin_hi"].values, (std::vector<double>{2, 4, 6, 8}));
  EXPECT_EQ(t["bin_center"].values, (std::vector<double>{1, 3, 5, 7}));
  EXPECT_EQ(t["count"].values, (std::vector<double>{2, 2, 2, 3}));
  // density = count / (N * width) with N = 9 finite values (the NaN is not counted).
  const std::vector<double> d = t["density"].values;
  EXPECT_DOUBLE_EQ(d[0], 2.0 / 18.0);
  EXPECT_DOUBLE_EQ(d[3], 3.0 / 18.0);
  EXPECT_DOUBLE_EQ(pdf_integral(t), 1.0);
  EXPECT_EQ(probability_density(v, o)["density"].unit, "");
}

TEST(ProbabilityDensity, DefaultRangeIntegratesToOne) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g(-3, 0.7);
  std::vector<double> v(5000);
  for (double& x : v)
    x = g(rng);
  v.push_back(kNaN);
  DensityOptions o;
  o.bins = 37;
  const Table t = probability_density(v, o);
  ASSERT_EQ(t.rows(), 37u);
  EXPECT_EQ(pdf_total_count(t), 5000.0);
  EXPECT_NEAR(pdf_integral(t), 1.0, 1e-12);
  const double width = t["bin_hi"].values[0] - t["bin_lo"].values[0];
  for (std::size_t i = 0; i < t.rows(); ++i) {
    const double w = t["bin_hi"].values[i] - t["bin_lo"].values[i];
    EXPECT_NEAR(w, width, 1e-12);
    EXPECT_DOUBLE_EQ(t["density"].values[i], t["count"].values[i] / (5000 * w));
  }
  EXPECT_EQ(t["bin_lo"].values.front(), *std::min_element(v.begin(), v.end() - 1));
  EXPECT_EQ(t["bin_hi"].values.back(), *std::max_element(v.begin(), v.end() - 1));
  EXPECT_EQ(DensityOptions{}.bins, 50u);
  EXPECT_EQ(probability_density(v, {}).rows(), 50u);
}

TEST(ProbabilityDensity, ExplicitRangeCountsOutsideValuesInTheNormalisationOnly) {
  DensityOptions o;
  o.bins = 4;
  o.range = std::make_pair(0.0, 4.0);
  const Table t = probability_density({-5, 0.5, 1.5, 2.5, 10}, o);
  EXPECT_EQ(t["bin_lo"].values, (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(t["count"].values, (std::vector<double>{1, 1, 1, 0}));
  EXPECT_EQ(t["density"].values, (std::vector<double>{0.2, 0.2, 0.2, 0}));
  EXPECT_DOUBLE_EQ(pdf_integral(t), 0.6);  // the fraction of values inside the range
}

TEST(ProbabilityDensity, LogarithmicBins) {
  // Three decades from 1 to 1000; zero and negative values are outside every log bin but
  // count in the normalisation (N = 8).
  const std::vector<double> v = {1, 2, 20, 50, 500, 1000, 0, -3, kNaN};
  DensityOptions o;
  o.bins = 3;
  o.scale = BinScale::logarithmic;
  const Table t = probability_density(v, o, "um");
  ASSERT_EQ(t.rows(), 3u);
  const auto& lo = t["bin_lo"].values;
  const auto& hi = t["bin_hi"].values;
  const auto& mid = t["bin_center"].values;
  EXPECT_EQ(lo[0], 1.0);
  EXPECT_EQ(hi[2], 1000.0);
  const double edges[] = {1, 10, 100, 1000};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(lo[i], edges[i], 1e-12 * edges[i]);
    EXPECT_NEAR(hi[i], edges[i + 1], 1e-12 * edges[i + 1]);
    EXPECT_NEAR(hi[i] / lo[i], 10.0, 1e-12);             // equal ratios
    EXPECT_DOUBLE_EQ(mid[i], std::sqrt(lo[i] * hi[i]));  // geometric centre
    if (i > 0) {
      EXPECT_EQ(lo[i], hi[i - 1]);
    }
  }
  EXPECT_NEAR(mid[1], std::sqrt(1000.0), 1e-12);
  EXPECT_EQ(t["count"].values, (std::vector<double>{2, 2, 2}));
  EXPECT_NEAR(t["density"].values[0], 2.0 / (8 * 9), 1e-15);
  EXPECT_NEAR(t["density"].values[1], 2.0 / (8 * 90), 1e-15);
  EXPECT_NEAR(t["density"].values[2], 2.0 / (8 * 900), 1e-15);
  EXPECT_NEAR(pdf_integral(t), 0.75, 1e-12);  // 6 of 8 finite values are in a bin

  // Without the non-positive values the default range holds everything.
  const Table all = probability_density({1, 2, 20, 50, 500, 1000}, o);
  EXPECT_NEAR(pdf_integral(all), 1.0, 1e-12);
}

TEST(ProbabilityDensity, AllValuesEqualGiveOneBinAroundThem) {
  DensityOptions o;
  o.bins = 1;
  const Table t = probability_density({3, 3, 3}, o);
  ASSERT_EQ(t.rows(), 1u);
  EXPECT_LT(t["bin_lo"].values[0], 3.0);
  EXPECT_GT(t["bin_hi"].values[0], 3.0);
  EXPECT_EQ(t["count"].values[0], 3.0);
  EXPECT_NEAR(pdf_integral(t), 1.0, 1e-9);
}

TEST(ProbabilityDensity, InvalidRangeIsAnError) {
  DensityOptions o;
  o.range = std::make_pair(5.0, 5.0);
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);
  o.range = std::make_pair(6.0, 2.0);
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);
  o.range = std::make_pair(kNaN, 2.0);
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);
  o.range = std::make_pair(0.0, kInf);
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);
  o.range = std::make_pair(0.0, 10.0);
  o.scale = BinScale::logarithmic;
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);  // log bins need range > 0
  o.range = std::make_pair(-1.0, 10.0);
  EXPECT_THROW(probability_density({1, 2, 3}, o), Error);
  o.range.reset();
  EXPECT_THROW(probability_density({0, -1, kNaN}, o), Error);  // nothing above zero
  o.scale = BinScale::linear;
  EXPECT_THROW(probability_density({}, o), Error);
  EXPECT_THROW(probability_density({kNaN, kNaN}, o), Error);
  o.bins = 0;
  EXPECT_THROW(probability_density({1, 2}, o), Error);
  // The control: the same options with a valid range work.
  o.bins = 2;
  o.range = std::make_pair(0.0, 10.0);
  EXPECT_EQ(probability_density({1, 2, 3}, o)["count"].values, (std::vector<double>{3, 0}));
}

TEST(DensityOptions, ValidateRefusesNoBinsAndAGivenRangeThatCannotHoldBins) {
  using testing::error_message;
  EXPECT_NO_THROW(DensityOptions{}.validate());
  DensityOptions o;
  o.bins = 0;
  EXPECT_EQ(error_message([&] { o.validate(); }), "pdf: the number of bins must be at least 1");
  o.bins = 10;
  o.range = std::make_pair(3.0, 3.0);
  EXPECT_EQ(error_message([&] { o.validate(); }),
            "pdf: empty value range (no finite values, or a range with low >= high)");
  o.range = std::make_pair(0.0, 3.0);
  EXPECT_NO_THROW(o.validate());
  o.scale = BinScale::logarithmic;
  EXPECT_EQ(error_message([&] { o.validate(); }), "pdf: logarithmic bins need a range above zero");
}

TEST(Median, OfTheFiniteValuesWithTheMiddleTwoAveraged) {
  EXPECT_EQ(median({3, 1, 2}), 2);
  EXPECT_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_EQ(median({kNaN, 5, kInf, 1}), 3);
  EXPECT_TRUE(std::isnan(median({kNaN})));
}

// The bootstrap's standard error of a mean is sigma / sqrt(n) for independent values.
TEST(BootstrapStandardError, IsSigmaOverRootNForIndependentValues) {
  Random draw(7), resample(8);
  std::vector<double> values;
  for (int k = 0; k < 400; ++k)
    values.push_back(2.0 + 0.5 * draw.normal());
  const Summary s = summarize(values);
  const double sigma = std::sqrt(s.mean_square - s.mean * s.mean);
  const double expected = sigma / std::sqrt(400.0);
  EXPECT_NEAR(bootstrap_standard_error(values, 2000, resample), expected, 0.06 * expected);
  values.push_back(kNaN);  // not measured: left out
  EXPECT_NEAR(bootstrap_standard_error(values, 2000, resample), expected, 0.06 * expected);
  EXPECT_EQ(bootstrap_standard_error(std::vector<double>(10, 1.0), 100, resample), 0);
  EXPECT_TRUE(std::isnan(bootstrap_standard_error({1.0}, 100, resample)));
}

// numpy.quantile's default (linear interpolation between order statistics).
TEST(Quantile, InterpolatesBetweenOrderStatisticsAsNumpyDoes) {
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_EQ(quantile(v, 0.0), 1.0);
  EXPECT_EQ(quantile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.25), 1.75);  // numpy.quantile([1, 2, 3, 4], 0.25)
  EXPECT_EQ(quantile(v, 0.5), 2.5);
  EXPECT_EQ(median(v), 2.5);
  std::vector<double> eleven;
  for (int k = 11; k >= 1; --k)
    eleven.push_back(k);
  EXPECT_EQ(quantile(eleven, 0.9), 10.0);  // exactly on an order statistic
  EXPECT_DOUBLE_EQ(quantile(eleven, 0.98), 10.8);
}

TEST(Quantile, IgnoresNonFiniteValuesAndIsNanWithoutAny) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> v = {nan, 5, inf, 1, 3};
  EXPECT_EQ(quantile(v, 0.5), 3.0);
  EXPECT_EQ(quantile_in_place(v, 1.0), 5.0);
  EXPECT_EQ(v.size(), 3u);  // the in-place form drops them
  EXPECT_TRUE(std::isnan(quantile({nan, inf}, 0.5)));
  EXPECT_TRUE(std::isnan(quantile({}, 0.5)));
}

TEST(MeanOfSmallest, AveragesTheSmallestValuesWhateverTheirOrder) {
  EXPECT_DOUBLE_EQ(mean_of_smallest({5, 1, 4, 2, 3}, 2), 1.5);
  EXPECT_DOUBLE_EQ(mean_of_smallest({5, 1, 4, 2, 3}, 1), 1);
  EXPECT_DOUBLE_EQ(mean_of_smallest({5, 1, 4}, 10), 10.0 / 3);  // all of them
  EXPECT_TRUE(std::isnan(mean_of_smallest({}, 3)));
  EXPECT_TRUE(std::isnan(mean_of_smallest({1, 2}, 0)));
}

TEST(EndLayerMean, AveragesAQuarterOfALayersGrains) {
  // A face of 12 d^2 holds 12 grains a layer: the 3 nearest; a tiny face still one.
  const double r = 0.5;
  EXPECT_DOUBLE_EQ(end_layer_mean({7, 3, 1, 9, 2, 8}, 12 * 4 * r * r, r), 2);
  EXPECT_DOUBLE_EQ(end_layer_mean({7, 3, 1, 9}, 0.01, r), 1);
}

}  // namespace
}  // namespace granmem
