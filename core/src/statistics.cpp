#include "granmem/core/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "granmem/core/error.hpp"

namespace granmem {

double quantile_in_place(std::vector<double>& values, double p) {
  values.erase(
      std::remove_if(values.begin(), values.end(), [](double x) { return !std::isfinite(x); }),
      values.end());
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double at = std::clamp(p, 0.0, 1.0) * double(values.size() - 1);
  const auto i = std::size_t(at);
  const double f = at - double(i);
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(i), values.end());
  const double lower = values[i];
  if (f == 0) return lower;
  const double upper = *std::min_element(values.begin() + std::ptrdiff_t(i) + 1, values.end());
  // (1 - f) lower + f upper: at f = 1/2 exactly half the sum of the middle two.
  return (1 - f) * lower + f * upper;
}

double quantile(std::vector<double> values, double p) {
  return quantile_in_place(values, p);
}

double median(std::vector<double> values) {
  return quantile_in_place(values, 0.5);
}

double mean_of_smallest(std::vector<double> values, std::size_t count) {
  count = std::min(count, values.size());
  if (count == 0) return std::nan("");
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(count - 1), values.end());
  double sum = 0;
  for (std::size_t k = 0; k < count; ++k)
    sum += values[k];
  return sum / double(count);
}

double end_layer_mean(std::vector<double> surfaces, double face, double radius) {
  const double grains = std::max(1.0, std::round(face / (16 * radius * radius)));
  return mean_of_smallest(std::move(surfaces), std::size_t(grains));
}

double bootstrap_standard_error(const std::vector<double>& values, std::size_t resamples,
                                Random& random) {
  std::vector<double> v;
  for (double x : values) {
    if (std::isfinite(x)) v.push_back(x);
  }
  if (v.size() < 2 || resamples < 2) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0, sum_sq = 0;
  for (std::size_t b = 0; b < resamples; ++b) {
    double total = 0;
    for (std::size_t k = 0; k < v.size(); ++k)
      total += v[std::min(v.size() - 1, std::size_t(random.uniform() * double(v.size())))];
    const double mean = total / double(v.size());
    sum += mean;
    sum_sq += mean * mean;
  }
  const double n = double(resamples), mean = sum / n;
  return std::sqrt(std::max(0.0, (sum_sq - n * mean * mean) / (n - 1)));
}

Summary summarize(const std::vector<double>& values) {
  std::vector<double> v;
  v.reserve(values.size());
  for (double x : values) {
    if (std::isfinite(x)) v.push_back(x);
  }
  Summary s;
  s.count = v.size();
  if (v.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.mean = s.median = s.mean_square = nan;
    return s;
  }
  double sum = 0, sum_sq = 0;
  for (double x : v) {
    sum += x;
    sum_sq += x * x;
  }
  s.mean = sum / double(v.size());
  s.mean_square = sum_sq / double(v.size());
  s.median = median(std::move(v));
  return s;
}

namespace {

Error empty_range(bool log) {
  return Error("pdf: empty value range (no finite values" + std::string(log ? " above zero" : "") +
               ", or a range with low >= high)");
}
const char* const kLogRange = "pdf: logarithmic bins need a range above zero";

}  // namespace

void DensityOptions::validate() const {
  if (bins == 0) throw Error("pdf: the number of bins must be at least 1");
  if (!range) return;
  const auto [lo, hi] = *range;
  const bool log = scale == BinScale::logarithmic;
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi)) throw empty_range(log);
  if (log && lo <= 0) throw Error(kLogRange);
}

Table probability_density(const std::vector<double>& values, const DensityOptions& options,
                          const std::string& unit) {
  options.validate();
  const bool log = options.scale == BinScale::logarithmic;
  std::size_t finite = 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double x : values) {
    if (!std::isfinite(x)) continue;
    ++finite;
    if (log && x <= 0) continue;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  if (options.range) std::tie(lo, hi) = *options.range;
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi)) {
    if (finite > 0 && lo == hi && !options.range) {
      // Every value equal: one bin around it keeps the table meaningful.
      const double pad = lo == 0 ? 1 : std::abs(lo) * 1e-6;
      hi = lo + pad;
      lo = log ? lo / (1 + 1e-6) : lo - pad;
    } else {
      throw empty_range(log);
    }
  }
  if (log && lo <= 0) throw Error(kLogRange);

  const std::size_t nb = options.bins;
  std::vector<double> edges(nb + 1);
  for (std::size_t i = 0; i <= nb; ++i) {
    const double f = double(i) / double(nb);
    edges[i] = log ? lo * std::pow(hi / lo, f) : lo + (hi - lo) * f;
  }
  edges.front() = lo;
  edges.back() = hi;

  std::vector<double> count(nb, 0);
  for (double x : values) {
    if (!std::isfinite(x) || x < lo || x > hi) continue;
    // Bin by search over the edges, so that the bin agrees with the edges written out.
    std::size_t b = std::size_t(std::upper_bound(edges.begin(), edges.end(), x) - edges.begin());
    b = std::min(std::max<std::size_t>(b, 1), nb) - 1;
    count[b] += 1;
  }

  Table t;
  Column& c_lo = t.add("bin_lo", unit);
  Column& c_hi = t.add("bin_hi", unit);
  Column& c_mid = t.add("bin_center", unit);
  Column& c_count = t.add("count", "", true);
  Column& c_density = t.add("density", unit.empty() ? "" : "1/" + unit);
  for (std::size_t i = 0; i < nb; ++i) {
    c_lo.values.push_back(edges[i]);
    c_hi.values.push_back(edges[i + 1]);
    c_mid.values.push_back(log ? std::sqrt(edges[i] * edges[i + 1])
                               : 0.5 * (edges[i] + edges[i + 1]));
    c_count.values.push_back(count[i]);
    c_density.values.push_back(finite ? count[i] / (double(finite) * (edges[i + 1] - edges[i]))
                                      : 0);
  }
  return t;
}

double student_t_975(double dof) {
  const double z = 1.959964, z3 = z * z * z, z5 = z3 * z * z;
  if (!(dof > 0) || !std::isfinite(dof)) return z;
  return z + (z3 + z) / (4 * dof) + (5 * z5 + 16 * z3 + 3 * z) / (96 * dof * dof) +
         (3 * z5 * z * z + 19 * z5 + 17 * z3 - 15 * z) / (384 * dof * dof * dof);
}

}  // namespace granmem
