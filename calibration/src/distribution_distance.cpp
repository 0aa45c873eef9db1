#include "granmem/calibration/distribution_distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

std::vector<double> sorted_finite(std::vector<double> v, const char* what) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) throw Error(std::string(what) + ": a sample has no finite value");
  std::sort(v.begin(), v.end());
  return v;
}

// Walks the merged sorted samples; at each step calls f(gap to the next value, F_a, F_b)
// with the two empirical CDFs just after the current value.
template <class F>
void walk_cdfs(const std::vector<double>& a, const std::vector<double>& b, F&& f) {
  std::size_t i = 0, j = 0;
  const double na = double(a.size()), nb = double(b.size());
  while (i < a.size() || j < b.size()) {
    const double x = j == b.size() || (i < a.size() && a[i] <= b[j]) ? a[i] : b[j];
    while (i < a.size() && a[i] == x)
      ++i;
    while (j < b.size() && b[j] == x)
      ++j;
    const bool more = i < a.size() || j < b.size();
    const double next = !more ? x : j == b.size() || (i < a.size() && a[i] <= b[j]) ? a[i] : b[j];
    f(next - x, double(i) / na, double(j) / nb);
  }
}

}  // namespace

double ks_distance(std::vector<double> a, std::vector<double> b) {
  a = sorted_finite(std::move(a), "KS distance");
  b = sorted_finite(std::move(b), "KS distance");
  double d = 0;
  walk_cdfs(a, b, [&](double, double fa, double fb) { d = std::max(d, std::abs(fa - fb)); });
  return d;
}

double wasserstein1_distance(std::vector<double> a, std::vector<double> b) {
  a = sorted_finite(std::move(a), "Wasserstein distance");
  b = sorted_finite(std::move(b), "Wasserstein distance");
  double w = 0;
  walk_cdfs(a, b, [&](double gap, double fa, double fb) { w += gap * std::abs(fa - fb); });
  return w;
}

double ks_p_value(double d, std::size_t n, std::size_t m) {
  if (n == 0 || m == 0) return std::nan("");
  const double ne = double(n) * double(m) / double(n + m);
  const double sq = std::sqrt(ne);
  const double lambda = (sq + 0.12 + 0.11 / sq) * d;
  if (lambda < 1e-3) return 1.0;
  // Q_KS(lambda) = 2 sum_k (-1)^(k-1) exp(-2 k^2 lambda^2)
  double sum = 0, sign = 1;
  for (int k = 1; k <= 100; ++k) {
    const double term = sign * std::exp(-2.0 * k * k * lambda * lambda);
    sum += term;
    if (std::abs(term) < 1e-12 * std::abs(sum)) break;
    sign = -sign;
  }
  return std::clamp(2 * sum, 0.0, 1.0);
}

}  // namespace granmem
