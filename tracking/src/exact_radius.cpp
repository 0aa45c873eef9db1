#include "exact_radius.hpp"

#include <algorithm>
#include <cmath>

namespace granmem {

ExactRadius fit_exact_radius(const std::vector<double>& model, const std::vector<double>& exact) {
  // One pass (Welford): the means, the model radii's spread and their co-spread.
  double n = 0, mean_model = 0, mean_exact = 0, variance = 0, covariance = 0;
  for (std::size_t k = 0; k < std::min(model.size(), exact.size()); ++k) {
    if (!std::isfinite(model[k]) || !std::isfinite(exact[k])) continue;
    n += 1;
    const double d_model = model[k] - mean_model;
    mean_model += d_model / n;
    mean_exact += (exact[k] - mean_exact) / n;
    variance += d_model * (model[k] - mean_model);
    covariance += d_model * (exact[k] - mean_exact);
  }
  if (n == 0) return {};
  const double slope = variance > 0 ? std::clamp(covariance / variance, 0.0, 1.0) : 1.0;
  return {mean_exact - slope * mean_model, slope};
}

}  // namespace granmem
