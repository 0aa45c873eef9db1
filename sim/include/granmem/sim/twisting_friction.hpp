#pragma once

#include <cmath>

#include "granmem/sim/contact_geometry.hpp"
#include "granmem/sim/contact_parameters.hpp"
#include "granmem/core/inline.hpp"

namespace granmem {

// Twisting friction with shape parameter beta: a spring-dashpot-slider of stiffness
// k_t beta^2/2, dashpot C_t beta^2/2 and cap mu_t mu_s beta |F_n|, driven by the twisting
// velocity v_tw = l_ij (w_i - w_j) . n, acting through the lever l_ij: the moment on i is
// l_ij F_tw n, on j the opposite, so that it resists the relative spin about n.
// mu_t = 0 is the do-nothing variant.
struct TwistingFriction {
  bool enabled = false;
  double k = 0, inv_k = 0;
  double damping_per_sqrt_mass = 0;
  double cap_per_normal_force = 0;  // mu_t mu_s beta

  TwistingFriction(const ContactParameters& p, double mu_t, double mu_s)
      : enabled(mu_t > 0 && mu_s > 0 && p.beta > 0),
        k(p.k_t() * p.beta * p.beta / 2.0),
        inv_k(k > 0 ? 1 / k : 0),
        damping_per_sqrt_mass(dashpot_coefficient(p.k_t(), p.restitution_t, 1.0) * p.beta * p.beta /
                              2.0),
        cap_per_normal_force(mu_t * mu_s * p.beta) {}

  GRANMEM_INLINE static double velocity(const ContactGeometry& g) {
    return g.l_ij * (g.w_i - g.w_j).dot(g.n);
  }

  struct Result {
    double force = 0;   // the moment on i is l_ij * force * n
    double spring = 0;  // history after this step
  };
  GRANMEM_INLINE Result evaluate(const ContactGeometry& g, double normal_force, double spring,
                                 double dt) const {
    const double v = velocity(g);
    const double c = damping_per_sqrt_mass * g.sqrt_reduced_mass;
    const double cap = cap_per_normal_force * std::abs(normal_force);
    Result r;
    r.spring = spring + v * dt;
    r.force = -k * r.spring - c * v;
    const bool slips = std::abs(r.force) > cap;
    r.force = slips ? std::copysign(cap, r.force) : r.force;
    r.spring = slips ? -inv_k * (r.force + c * v) : r.spring;
    return r;
  }
};

}  // namespace granmem
