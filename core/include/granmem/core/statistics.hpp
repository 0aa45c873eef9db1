#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/random.hpp"
#include "granmem/core/table.hpp"

namespace granmem {

// Count, mean, median and mean square of the finite values (NaN marks "not measured").
struct Summary {
  std::size_t count = 0;
  double mean = 0;
  double median = 0;
  double mean_square = 0;
};
Summary summarize(const std::vector<double>& values);

// The p-quantile (0 <= p <= 1) of the finite values: linear interpolation between the
// order statistics around p (n - 1) (numpy's default), so p = 0.5 is the median, the mean
// of the middle two for an even count; NaN if there are none. granmem's one convention for
// medians, percentiles and quantiles.
double quantile(std::vector<double> values, double p);
// The same in O(n) on the caller's vector, which loses its non-finite values and its
// order (for large samples, e.g. a slice's voxels).
double quantile_in_place(std::vector<double>& values, double p);
// quantile(values, 0.5).
double median(std::vector<double> values);
// The mean of the `count` smallest values (all of them if fewer; NaN if none), in O(n):
// a packing's end layer, less noisy than its one extreme grain.
double mean_of_smallest(std::vector<double> values, std::size_t count);
// Where a packing ends at a wall, floor or lid: the mean of the smallest `surfaces` (the
// grains' surfaces facing it, signed so that the nearest are the smallest) over a quarter
// of a layer's grains, the face's area over 4 d^2 for grains of radius `radius` (at least
// one).
double end_layer_mean(std::vector<double> surfaces, double face, double radius);

// The 97.5 % point of Student's t with `dof` degrees of freedom (Cornish-Fisher expansion
// about the normal's 1.96; within 0.2 % for dof >= 3; the normal's for dof <= 0): a 95 %
// interval's multiplier when a variance is itself estimated from few values.
double student_t_975(double dof);

// The standard error of the mean of the finite values, from `resamples` bootstrap draws of
// as many values with replacement: the spread of the mean over resamples of the grains.
// NaN with fewer than two values.
double bootstrap_standard_error(const std::vector<double>& values, std::size_t resamples,
                                Random& random);

enum class BinScale { linear, logarithmic };

struct DensityOptions {
  std::size_t bins = 50;
  BinScale scale = BinScale::linear;
  // Histogram range; default the finite values' min and max (smallest positive value for
  // logarithmic bins).
  std::optional<std::pair<double, double>> range;

  // Throws Error for no bins, or a range given that is empty, not finite, or (logarithmic
  // bins) not above zero.
  void validate() const;
};

// The probability density of `values` in bins of equal width (linear) or equal ratio
// (logarithmic): count / (finite values * bin width), so that it integrates to the
// fraction of values inside the range (1 with the default range). NaN values are not
// counted; values outside the range, zeros on log bins among them, count in the
// normalisation only. Columns: bin_lo, bin_hi, bin_center (geometric centre for log
// bins), count, density. Throws Error if the range is empty or invalid.
Table probability_density(const std::vector<double>& values, const DensityOptions& options,
                          const std::string& unit = "");

}  // namespace granmem
