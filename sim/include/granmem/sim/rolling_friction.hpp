#pragma once

#include "granmem/sim/contact_geometry.hpp"
#include "granmem/sim/contact_parameters.hpp"
#include "granmem/core/inline.hpp"
#include "granmem/sim/sliding_friction.hpp"

namespace granmem {

// Rolling friction with shape parameter beta (Zhang et al. 2018): a spring-dashpot-slider
// of stiffness k_n beta^2/4, dashpot C_n beta^2/4 and cap mu_r beta |F_n|, driven by the
// rolling velocity v_r = l_i (w_i x n) - l_j (w_j x n), acting through the lever l_ij: the
// moment on i is l_ij n x F_r, on j the opposite. mu_r = 0 is the do-nothing variant.
struct RollingFriction {
  bool enabled = false;
  double k = 0, inv_k = 0;
  double damping_per_sqrt_mass = 0;
  double cap_per_normal_force = 0;  // mu_r beta

  explicit RollingFriction(const ContactParameters& p, double mu_r)
      : enabled(mu_r > 0 && p.beta > 0),
        k(p.k_n * p.beta * p.beta / 4.0),
        inv_k(k > 0 ? 1 / k : 0),
        damping_per_sqrt_mass(dashpot_coefficient(p.k_n, p.restitution_n, 1.0) * p.beta * p.beta /
                              4.0),
        cap_per_normal_force(mu_r * p.beta) {}

  GRANMEM_INLINE static Eigen::Vector3d velocity(const ContactGeometry& g) {
    return g.wall ? g.l_i * g.w_i.cross(g.n) : (g.l_i * g.w_i - g.l_j * g.w_j).cross(g.n);
  }

  // The spring-slider; the moment on i is g.l_ij * n x force.
  GRANMEM_INLINE SpringSlider evaluate(const ContactGeometry& g, double normal_force,
                                       const Eigen::Vector3d& spring, double dt) const {
    return spring_slider(spring, g.n, velocity(g), dt, k, inv_k,
                         damping_per_sqrt_mass * g.sqrt_reduced_mass,
                         cap_per_normal_force * std::abs(normal_force));
  }
};

}  // namespace granmem
