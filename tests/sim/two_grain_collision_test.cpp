// Analytic two-body benchmarks of the contact law (the LAMMPS GRANULAR test ladder).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "granmem/sim/simulation.hpp"

namespace granmem {
namespace {

constexpr double kRadius = 0.0025, kDensity = 1180;

// No gravity, no walls in reach: a free two-grain system.
PhysicsOptions free_space() {
  PhysicsOptions p;
  p.gravity = 0;
  return p;
}

Container far_walls() {
  Container c;
  c.size = {10, 10};
  return c;
}

TEST(TwoGrainCollision, HeadOnRestitutionAndDurationMatchTheDampedSpring) {
  for (double e : {0.2, 0.5, 0.9}) {
    PhysicsOptions p = free_space();
    p.contact.restitution_n = e;
    // Fine steps: compare with the continuous solution. (The explicit scheme's error comes
    // from the step in which the contact ends, ~C dt / m: 1% at 1 us, 8% at 25 us for e = 0.2.)
    p.dt = 2e-7;
    Grains g;
    g.add(0, {5, 5, 5}, kRadius, kDensity);
    g.add(1, {5 + 2 * kRadius + 1e-5, 5, 5}, kRadius, kDensity);
    const double v0 = 0.1;
    g.v[0] = {v0, 0, 0};
    g.v[1] = {-v0, 0, 0};
    Simulation sim(g, far_walls(), p);
    double first = -1, last = -1;
    for (int s = 0; s < 4000; ++s) {
      sim.step();
      if (sim.contact_count() > 0) {
        if (first < 0) first = sim.time();
        last = sim.time();
      }
    }
    const double m = sim.grains().mass[0];
    const double approach = 2 * v0;
    const double separation = sim.grains().v[1].x() - sim.grains().v[0].x();
    EXPECT_NEAR(separation / approach, e, 0.01 * e) << "e " << e;
    const double expected = contact_duration(p.contact.k_n, e, m / 2);
    EXPECT_NEAR(last - first + p.dt, expected, 0.01 * expected) << "e " << e;
    // No friction acts on a head-on collision: no spin.
    EXPECT_LT(sim.grains().w[0].norm(), 1e-12);
  }
}

// While it slides, Coulomb friction mu m g decelerates it at mu g and spins it up at
// (5/2) mu g / R; sliding stops when v = R w, at t* = 2 v0 / (7 mu g), at v = 5/7 v0
// (angular momentum about the contact point is conserved). Then it rolls on.
TEST(TwoGrainCollision, SlidingGrainRollsAtFiveSeventhsOfItsSpeed) {
  PhysicsOptions p;
  p.contact.mu_r = 0;  // pure Coulomb sliding: the classic 5/7
  p.contact.mu_t = 0;
  const double mu = 0.3, v0 = 0.2, g_acc = 9.81;
  p.wall = {mu, 0, 0};
  Grains g;
  const double r = kRadius;
  g.add(0, {1, 1, r - 9.81 * 7.72e-5 / 4000}, r, kDensity);  // resting on its overlap
  g.v[0] = {v0, 0, 0};
  Container c;
  c.size = {10, 10};
  Simulation sim(g, c, p);
  const double t_star = 2 * v0 / (7 * mu * g_acc);  // 0.0194 s
  double slip_ends = -1;
  for (int s = 0; s < 8000; ++s) {  // 0.2 s
    sim.step();
    const Grains& now = sim.grains();
    if (s == 399) {  // t = 0.01 s, sliding
      EXPECT_NEAR(now.v[0].x(), v0 - mu * g_acc * 0.01, 1e-3 * v0);
      EXPECT_NEAR(now.w[0].y() * r, 2.5 * mu * g_acc * 0.01, 1e-3 * v0);
    }
    if (slip_ends < 0 && now.v[0].x() - now.w[0].y() * r < 1e-4 * v0) slip_ends = sim.time();
  }
  EXPECT_NEAR(slip_ends, t_star, 0.02 * t_star);
  RecordProperty("slip_ends_measured", std::to_string(slip_ends));
  RecordProperty("slip_ends_expected", std::to_string(t_star));
  const Grains& s = sim.grains();
  EXPECT_NEAR(s.v[0].x(), 5.0 / 7.0 * v0, 2e-3 * v0);
  EXPECT_NEAR(s.w[0].y() * r, s.v[0].x(), 2e-3 * v0);  // rolling without slipping
}

TEST(TwoGrainCollision, EnergyIsConservedWithoutDampingOrFriction) {
  PhysicsOptions p = free_space();
  p.contact.restitution_n = 1;
  p.contact.restitution_t = 1;
  p.contact.mu_s = 0;
  p.contact.mu_r = 0;
  p.contact.mu_t = 0;
  Grains g;
  g.add(0, {5, 5, 5}, kRadius, kDensity);
  g.add(1, {5 + 2 * kRadius + 1e-5, 5 + 0.3 * kRadius, 5}, kRadius, kDensity);
  g.v[0] = {0.3, 0.05, 0};
  g.v[1] = {-0.1, 0, 0.02};
  p.dt = 1e-6;  // the error left by a contact's kink at zero overlap is O(dt^2)
  Simulation sim(g, far_walls(), p);
  const double before = sim.kinetic_energy();
  sim.run(10000);
  EXPECT_NEAR(sim.kinetic_energy(), before, 1e-4 * before);
}

}  // namespace
}  // namespace granmem
