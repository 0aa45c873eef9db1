#pragma once

#include <string>

namespace granmem {

// The soft-sphere contact law of the paper's simulations (Schwartz, Richardson & Michel
// 2012; rolling and twisting after Zhang et al. 2018), SI units. Defaults: the paper's
// table. docs/CONTACT_MODEL.md has the equations.
struct ContactParameters {
  double k_n = 4000.0;              // normal spring, N/m (4e6 g/s^2)
  double restitution_n = 0.2;       // normal restitution; sets the normal dashpot
  double k_t_over_k_n = 5.0 / 7.0;  // tangential spring k_t = (5/7) k_n, as the paper states
  double restitution_t = 0.5;       // tangential restitution; sets the tangential dashpot
  double mu_s = 0.2;                // sliding (static) friction
  double mu_r = 0.01;               // rolling friction
  double mu_t = 0.001;              // twisting friction
  double beta = 0.5;                // shape parameter: beta * l_ij is the contact patch radius

  double k_t() const { return k_t_over_k_n * k_n; }
  // Throws Error naming `where` and the parameter for anything unphysical.
  void validate(const std::string& where) const;
};

// The dashpot that gives restitution e to a linear spring k between bodies of reduced
// mass m_red: C = 2 sqrt(m_red k) |ln e| / sqrt(pi^2 + ln^2 e). Zero for e = 1.
double dashpot_coefficient(double k, double restitution, double reduced_mass);

// Duration of a collision on a damped linear spring: pi / sqrt(k/m_red - (C / 2 m_red)^2).
double contact_duration(double k, double restitution, double reduced_mass);

}  // namespace granmem
