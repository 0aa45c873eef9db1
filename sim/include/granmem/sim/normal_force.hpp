#pragma once

#include <cmath>

#include "granmem/sim/contact_geometry.hpp"
#include "granmem/sim/contact_parameters.hpp"
#include "granmem/core/inline.hpp"

namespace granmem {

// Linear spring and dashpot along the normal: F_n = (k_n delta - C_n v_n) n on grain i.
// Not clipped at zero, so that a collision's restitution is exactly the set one.
struct NormalForce {
  double k = 0;
  double damping_per_sqrt_mass = 0;  // C_n / sqrt(m_red)

  explicit NormalForce(const ContactParameters& p)
      : k(p.k_n), damping_per_sqrt_mass(dashpot_coefficient(p.k_n, p.restitution_n, 1.0)) {}

  GRANMEM_INLINE double damping(const ContactGeometry& g) const {
    return damping_per_sqrt_mass * g.sqrt_reduced_mass;
  }
  // Signed magnitude along n (> 0 pushes i away from j).
  GRANMEM_INLINE double magnitude(const ContactGeometry& g) const {
    return k * g.overlap - damping(g) * g.v_n;
  }
};

}  // namespace granmem
