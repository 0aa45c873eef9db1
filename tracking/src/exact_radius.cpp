#include "exact_radius.hpp"

#include <algorithm>
#include <cmath>

namespace granmem {

ExactRadius fit_exact_radius(const std::vector<double>& model, const std::vector<double>& exact) {
  double n = 0, mean_model = 0, mean_exact = 0;
  for (std::size_t k = 0; k < std::min(model.size(), exact.size()); ++k) {
    if (!std::isfinite(model[k]) || !std::isfinite(exact[k])) continue;
    n += 1;
    mean_model += (model[k] - mean_model) / n;
    mean_exact += (exact[k] - mean_exact) / n;
  }
  if (n == 0) return {};
  double covariance = 0, variance = 0;
  for (std::size_t k = 0; k < std::min(model.size(), exact.size()); ++k) {
    if (!std::isfinite(model[k]) || !std::isfinite(exact[k])) continue;
    covariance += (model[k] - mean_model) * (exact[k] - mean_exact);
    variance += (model[k] - mean_model) * (model[k] - mean_model);
  }
  const double slope = variance > 0 ? std::clamp(covariance / variance, 0.0, 1.0) : 1.0;
  return {mean_exact - slope * mean_model, slope};
}

}  // namespace granmem
