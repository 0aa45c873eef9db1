#include "granmem/sim/contact_parameters.hpp"

#include <cmath>

#include "granmem/core/error.hpp"

namespace granmem {

void ContactParameters::validate(const std::string& where) const {
  auto require = [&](bool ok, const char* name, const char* what) {
    if (!ok) throw Error(where + ": " + name + " must be " + what);
  };
  require(std::isfinite(k_n) && k_n > 0, "k_n", "a positive stiffness");
  require(std::isfinite(k_t_over_k_n) && k_t_over_k_n >= 0, "k_t/k_n", "zero or positive");
  require(restitution_n > 0 && restitution_n <= 1, "restitution_n", "in (0, 1]");
  require(restitution_t > 0 && restitution_t <= 1, "restitution_t", "in (0, 1]");
  require(std::isfinite(mu_s) && mu_s >= 0, "mu_s", "zero or positive");
  require(std::isfinite(mu_r) && mu_r >= 0, "mu_r", "zero or positive");
  require(std::isfinite(mu_t) && mu_t >= 0, "mu_t", "zero or positive");
  require(std::isfinite(beta) && beta >= 0 && beta <= 1, "beta", "in [0, 1]");
}

double dashpot_coefficient(double k, double restitution, double reduced_mass) {
  const double log_e = std::log(restitution);
  return 2.0 * std::sqrt(reduced_mass * k) * std::abs(log_e) /
         std::sqrt(M_PI * M_PI + log_e * log_e);
}

double contact_duration(double k, double restitution, double reduced_mass) {
  const double c = dashpot_coefficient(k, restitution, reduced_mass);
  const double damping = c / (2.0 * reduced_mass);
  return M_PI / std::sqrt(k / reduced_mass - damping * damping);
}

}  // namespace granmem
