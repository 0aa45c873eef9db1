#pragma once

#include <Eigen/Core>

#include "granmem/sim/contact_geometry.hpp"
#include "granmem/sim/contact_parameters.hpp"
#include "granmem/core/inline.hpp"
#include "granmem/sim/normal_force.hpp"
#include "granmem/sim/rolling_friction.hpp"
#include "granmem/sim/sliding_friction.hpp"
#include "granmem/sim/twisting_friction.hpp"

namespace granmem {

// What a contact remembers over its life: the stretch of its three springs. Zero when the
// contact forms; forgotten when it breaks.
struct ContactHistory {
  Eigen::Vector3d slide = Eigen::Vector3d::Zero();
  Eigen::Vector3d roll = Eigen::Vector3d::Zero();
  double twist = 0;
};

// Forces and moments of one contact in one step, and the history it leaves.
struct ContactForces {
  Eigen::Vector3d force_on_i;  // the force on j is the opposite
  Eigen::Vector3d torque_on_i;
  Eigen::Vector3d torque_on_j;  // unused for a wall
  double normal_force = 0;      // signed, along n
  ContactHistory history;
};

// The paper's contact law, composed of its modes. Evaluating a contact is a pure function
// of its geometry and its history before the step: nothing changes until the caller
// stores the returned history, which the simulation does in one place.
class ContactModel {
 public:
  // `mu_s`, `mu_r`, `mu_t` may differ from the parameters' (walls have their own friction).
  ContactModel(const ContactParameters& p, double mu_s, double mu_r, double mu_t)
      : normal_(p), sliding_(p, mu_s), rolling_(p, mu_r), twisting_(p, mu_t, mu_s) {}
  explicit ContactModel(const ContactParameters& p) : ContactModel(p, p.mu_s, p.mu_r, p.mu_t) {}

  GRANMEM_INLINE ContactForces evaluate(const ContactGeometry& g, const ContactHistory& before,
                                        double dt) const {
    if (rolling_.enabled) {
      return twisting_.enabled ? evaluate_modes<true, true>(g, before, dt)
                               : evaluate_modes<true, false>(g, before, dt);
    }
    return twisting_.enabled ? evaluate_modes<false, true>(g, before, dt)
                             : evaluate_modes<false, false>(g, before, dt);
  }

  // The law with its rolling and twisting modes on or off at compile time: a loop over
  // contacts then has no branch (evaluate() above picks the modes the parameters enable).
  template <bool kRolling, bool kTwisting>
  GRANMEM_INLINE ContactForces evaluate_modes(const ContactGeometry& g,
                                              const ContactHistory& before, double dt) const {
    ContactForces out;
    const double fn = normal_.magnitude(g);
    out.normal_force = fn;
    const SpringSlider slide = sliding_.evaluate(g, fn, before.slide, dt);
    out.history.slide = slide.spring;
    out.force_on_i = fn * g.n + slide.force;
    // Moments about each centre: the tangential force acts at the contact point, -l n
    // from i's centre and +l n from j's; rolling and twisting act through l_ij.
    Eigen::Vector3d lever_i = -g.l_i * slide.force, lever_j = -g.l_j * slide.force;
    double twist_moment = 0;
    if constexpr (kRolling) {
      const SpringSlider roll = rolling_.evaluate(g, fn, before.roll, dt);
      out.history.roll = roll.spring;
      lever_i += g.l_ij * roll.force;
      lever_j -= g.l_ij * roll.force;
    }
    if constexpr (kTwisting) {
      const TwistingFriction::Result twist = twisting_.evaluate(g, fn, before.twist, dt);
      out.history.twist = twist.spring;
      twist_moment = g.l_ij * twist.force;
    }
    out.torque_on_i = g.n.cross(lever_i) + twist_moment * g.n;
    if (!g.wall) out.torque_on_j = g.n.cross(lever_j) - twist_moment * g.n;
    return out;
  }

  bool rolling() const { return rolling_.enabled; }
  bool twisting() const { return twisting_.enabled; }
  const NormalForce& normal() const { return normal_; }

 private:
  NormalForce normal_;
  SlidingFriction sliding_;
  RollingFriction rolling_;
  TwistingFriction twisting_;
};

}  // namespace granmem
