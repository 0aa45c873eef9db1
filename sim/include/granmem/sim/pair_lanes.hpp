#pragma once

#include <cstdint>

#include "granmem/sim/contact_model.hpp"

namespace granmem {

// A batch of touching grain pairs laid out by lane (one array per component), so that the
// contact law runs on several pairs per instruction. The caller fills the inputs and the
// springs before the step with add(), evaluate_pair_lanes() replaces the springs with
// their state after the step and writes the forces.
struct PairLanes {
  static constexpr int kCapacity = 64;
  int count = 0;
  std::uint32_t pair[kCapacity];  // the caller's index of each pair
  // Grain i (the owner) and grain j: centres, velocities, angular velocities, radii.
  double x_i[3][kCapacity], x_j[3][kCapacity];
  double v_i[3][kCapacity], v_j[3][kCapacity];
  double w_i[3][kCapacity], w_j[3][kCapacity];
  double r_i[kCapacity], r_j[kCapacity];
  double sqrt_reduced_mass[kCapacity];
  // The springs (ContactHistory): before the step, then after it.
  double slide[3][kCapacity], roll[3][kCapacity], twist[kCapacity];
  // The force on i (on j the opposite) and the moments on i and on j.
  double force_on_i[3][kCapacity], torque_on_i[3][kCapacity], torque_on_j[3][kCapacity];

  bool full() const { return count == kCapacity; }
  // Appends pair `index` between grains at x_i and x_j; the caller empties a full batch
  // (evaluate_pair_lanes, then count = 0) before adding more.
  void add(std::uint32_t index, const Eigen::Vector3d& xi, const Eigen::Vector3d& xj,
           const Eigen::Vector3d& vi, const Eigen::Vector3d& vj, const Eigen::Vector3d& wi,
           const Eigen::Vector3d& wj, double ri, double rj, double sqrt_m,
           const ContactHistory& before) {
    const int l = count++;
    pair[l] = index;
    for (int a = 0; a < 3; ++a) {
      x_i[a][l] = xi[a];
      x_j[a][l] = xj[a];
      v_i[a][l] = vi[a];
      v_j[a][l] = vj[a];
      w_i[a][l] = wi[a];
      w_j[a][l] = wj[a];
      slide[a][l] = before.slide[a];
      roll[a][l] = before.roll[a];
    }
    r_i[l] = ri;
    r_j[l] = rj;
    sqrt_reduced_mass[l] = sqrt_m;
    twist[l] = before.twist;
  }
  ContactHistory history(int l) const {
    ContactHistory h;
    h.slide = {slide[0][l], slide[1][l], slide[2][l]};
    h.roll = {roll[0][l], roll[1][l], roll[2][l]};
    h.twist = twist[l];
    return h;
  }
};

// The contact law (ContactModel::evaluate on sphere_contact) for every lane, to rounding (the
// one-pair law elsewhere may use Eigen's SSE code or fused multiply-adds). A pair's result
// does not depend on its place in the batch. With GCC on x86-64 Linux it is built for
// AVX-512, AVX2 and the baseline, the widest the processor has chosen when the program
// loads, without fused multiply-adds, so that each width does the same arithmetic.
void evaluate_pair_lanes(const ContactModel& model, PairLanes& lanes, double dt);

}  // namespace granmem
