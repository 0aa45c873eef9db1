#include "granmem/sim/pair_lanes.hpp"

#include "granmem/core/inline.hpp"

namespace granmem {
namespace {

// One batch with the law's modes fixed, so that the loop has no branch and vectorises.
template <bool kRolling, bool kTwisting>
GRANMEM_INLINE void evaluate_lanes(const ContactModel& model, PairLanes& L, double dt) {
  const ContactModel m = model;  // a copy the lanes' stores cannot alias
  const int n = L.count;
  for (int l = 0; l < n; ++l) {
    const ContactGeometry g = sphere_contact(
        {L.x_i[0][l], L.x_i[1][l], L.x_i[2][l]}, {L.x_j[0][l], L.x_j[1][l], L.x_j[2][l]}, L.r_i[l],
        L.r_j[l], {L.v_i[0][l], L.v_i[1][l], L.v_i[2][l]}, {L.v_j[0][l], L.v_j[1][l], L.v_j[2][l]},
        {L.w_i[0][l], L.w_i[1][l], L.w_i[2][l]}, {L.w_j[0][l], L.w_j[1][l], L.w_j[2][l]},
        L.sqrt_reduced_mass[l]);
    const ContactForces f = m.evaluate_modes<kRolling, kTwisting>(g, L.history(l), dt);
    for (int a = 0; a < 3; ++a) {
      L.force_on_i[a][l] = f.force_on_i[a];
      L.torque_on_i[a][l] = f.torque_on_i[a];
      L.torque_on_j[a][l] = f.torque_on_j[a];
      L.slide[a][l] = f.history.slide[a];
      L.roll[a][l] = f.history.roll[a];
    }
    L.twist[l] = f.history.twist;
  }
}

}  // namespace

GRANMEM_LANE_TARGETS void evaluate_pair_lanes(const ContactModel& model, PairLanes& lanes,
                                              double dt) {
  if (model.rolling()) {
    if (model.twisting()) {
      evaluate_lanes<true, true>(model, lanes, dt);
    } else {
      evaluate_lanes<true, false>(model, lanes, dt);
    }
  } else if (model.twisting()) {
    evaluate_lanes<false, true>(model, lanes, dt);
  } else {
    evaluate_lanes<false, false>(model, lanes, dt);
  }
}

}  // namespace granmem
