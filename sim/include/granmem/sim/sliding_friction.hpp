#pragma once

#include <Eigen/Core>
#include <cmath>

#include "granmem/sim/contact_geometry.hpp"
#include "granmem/sim/contact_parameters.hpp"
#include "granmem/core/inline.hpp"

namespace granmem {

// Component-wise choice between two vectors: written without a branch, so that the
// compiler can evaluate a batch of contacts side by side (pair_lanes.hpp).
GRANMEM_INLINE Eigen::Vector3d select(bool first, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b) {
  return {first ? a.x() : b.x(), first ? a.y() : b.y(), first ? a.z() : b.z()};
}

// Keeps a contact spring in the current tangent plane: the part along n is removed and the
// length kept, so that a contact turning as a whole neither gains nor loses spring energy.
GRANMEM_INLINE Eigen::Vector3d onto_tangent_plane(const Eigen::Vector3d& spring,
                                                  const Eigen::Vector3d& n) {
  const double along = spring.dot(n);
  const Eigen::Vector3d t = spring - along * n;
  const double t_sq = t.squaredNorm();
  // Length kept: scale by sqrt(1 + along^2 / t^2) (1 for a spring along n, which has no
  // tangential part to keep). A contact turns little in one step, and below 1e-8 the
  // first order term is exact to double precision.
  const double ratio = t_sq > 0 ? along * along / t_sq : 0.0;
  return t * (ratio < 1e-8 ? 1.0 + 0.5 * ratio : std::sqrt(1.0 + ratio));
}

// A spring-dashpot capped by a Coulomb slider: F = -k s - C v, |F| <= cap. Where it slips,
// the spring is rewritten to match the capped force. Shared by sliding and rolling.
// Branch-free, like every mode of the law, so that contacts can be evaluated in batches.
struct SpringSlider {
  Eigen::Vector3d force;
  Eigen::Vector3d spring;  // history after this step
};
GRANMEM_INLINE SpringSlider spring_slider(const Eigen::Vector3d& spring_before,
                                          const Eigen::Vector3d& n, const Eigen::Vector3d& velocity,
                                          double dt, double k, double inv_k, double c, double cap) {
  SpringSlider out;
  out.spring = onto_tangent_plane(spring_before, n) + velocity * dt;
  out.force = -k * out.spring - c * velocity;
  const double f_sq = out.force.squaredNorm();
  const bool slips = f_sq > cap * cap;
  out.force *= slips ? cap / std::sqrt(f_sq) : 1.0;
  // A multiplication by 1/k: the slipping spring is the common case for rolling contacts,
  // whose slider is nearly always saturated.
  out.spring = select(slips, -inv_k * (out.force + c * velocity), out.spring);
  return out;
}

// Sliding friction: a tangential spring k_t that accumulates the tangential relative
// displacement over the life of a contact, a dashpot from the tangential restitution, and
// Coulomb's cap mu_s |F_n|. The torque on grain i is l_i (-n x F_t).
struct SlidingFriction {
  double k = 0, inv_k = 0;           // inv_k = 1/k, or 0 without a spring
  double damping_per_sqrt_mass = 0;  // C_t / sqrt(m_red)
  double mu = 0;

  SlidingFriction(const ContactParameters& p, double mu_s)
      : k(p.k_t()),
        inv_k(p.k_t() > 0 ? 1 / p.k_t() : 0),
        damping_per_sqrt_mass(dashpot_coefficient(p.k_t(), p.restitution_t, 1.0)),
        mu(mu_s) {}

  GRANMEM_INLINE SpringSlider evaluate(const ContactGeometry& g, double normal_force,
                                       const Eigen::Vector3d& spring, double dt) const {
    return spring_slider(spring, g.n, g.v_t, dt, k, inv_k,
                         damping_per_sqrt_mass * g.sqrt_reduced_mass, mu * std::abs(normal_force));
  }
};

}  // namespace granmem
