// Twisting friction: a sphere spinning about the vertical while resting on a body slows at a
// constant rate. Once the twisting slider is saturated its moment is
//   M = mu_t mu_s beta l_ij |F_n|   (about n, against the relative spin),
// so dw_z/dt = -M / I with I = 2/5 m R^2 and |F_n| = m g. The spin moves no contact point
// (n x w = 0) and rolls nothing (w x n = 0): no other mode acts. The lever l_ij is 2 d on the
// floor (d = R - m g / k_n, the centre's height) and d / 2 between two equal spheres whose
// centres are d = 2 R - m g / k_n apart.
#include <gtest/gtest.h>

#include <cmath>

#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kDensity;
using testing::kGravity;
using testing::kRadius;

constexpr double kMuS = 0.3, kMuT = 0.1, kSpin = 30;  // rad/s

PhysicsOptions twisting_physics() {
  PhysicsOptions p;
  p.gravity = kGravity;
  p.contact.mu_s = kMuS;
  p.contact.mu_t = kMuT;
  p.wall = {kMuS, 0.01, kMuT};
  return p;
}

// Angular deceleration of grain `i` about z between t1 and t2, and its spin at the end.
double spin_down_rate(Simulation& sim, std::size_t i, double t1, double t2) {
  const double dt = sim.physics().dt;
  sim.run(std::llround(t1 / dt));
  const double w1 = sim.grains().w[i].z();
  sim.run(std::llround((t2 - t1) / dt));
  return (sim.grains().w[i].z() - w1) / (t2 - t1);
}

TEST(TwistingFriction, SphereSpinningOnTheFloorSlowsAtTheCappedMoment) {
  const PhysicsOptions p = twisting_physics();
  Grains g;
  g.add(0, {0.5, 0.5, 0}, kRadius, kDensity);
  const double m = g.mass[0], inertia = 1 / g.inv_inertia[0];
  const double d = kRadius - testing::resting_overlap(m, p);
  g.x[0].z() = d;
  g.w[0] = {0, 0, kSpin};
  Simulation sim(g, testing::wide_box(1.0), p);
  const double expected = -kMuT * kMuS * p.contact.beta * (2 * d) * m * kGravity / inertia;
  const double measured = spin_down_rate(sim, 0, 0.01, 0.08);
  EXPECT_NEAR(measured, expected, 0.01 * std::abs(expected));
  RecordProperty("rate_measured", testing::number(measured));
  RecordProperty("rate_expected", testing::number(expected));
  // Nothing else moves.
  EXPECT_LT(sim.grains().v[0].norm(), 1e-9);
  EXPECT_EQ(sim.grains().w[0].x(), 0);
  EXPECT_EQ(sim.grains().w[0].y(), 0);
  // Stopped after w0 / |rate|, and held by the twisting spring.
  sim.run(std::llround((1.2 * kSpin / std::abs(expected) - 0.08) / p.dt));
  EXPECT_LT(std::abs(sim.grains().w[0].z()), 0.01 * kSpin);
}

// A grain spinning on top of another that rests on the floor: the pair's twisting moment has
// the lever l_ij = d / 2 and slows the top grain; the bottom grain's floor contact, whose cap
// (lever 2 d', load 2 m g) is about four times larger, holds it still.
TEST(TwistingFriction, GrainSpinningOnAGrainSlowsAtThePairsCappedMoment) {
  const PhysicsOptions p = twisting_physics();
  Grains g;
  g.add(0, {0.5, 0.5, 0}, kRadius, kDensity);
  g.add(1, {0.5, 0.5, 0}, kRadius, kDensity);
  const double m = g.mass[0], inertia = 1 / g.inv_inertia[0];
  const double sag = testing::resting_overlap(m, p);
  g.x[0].z() = kRadius - 2 * sag;
  const double d = 2 * kRadius - sag;
  g.x[1].z() = g.x[0].z() + d;
  g.w[1] = {0, 0, kSpin};
  Simulation sim(g, testing::wide_box(1.0), p);
  const double expected = -kMuT * kMuS * p.contact.beta * (d / 2) * m * kGravity / inertia;
  const double measured = spin_down_rate(sim, 1, 0.01, 0.08);
  EXPECT_NEAR(measured, expected, 0.01 * std::abs(expected));
  RecordProperty("rate_measured", testing::number(measured));
  RecordProperty("rate_expected", testing::number(expected));
  EXPECT_LT(std::abs(sim.grains().w[0].z()), 1e-3 * kSpin) << "the bottom grain turned";
  // The stack stays aligned: the forces are all along z.
  EXPECT_EQ(sim.grains().x[1].x(), 0.5);
  EXPECT_EQ(sim.grains().x[1].y(), 0.5);
}

// Without twisting friction, the spin persists.
TEST(TwistingFriction, WithoutTwistingFrictionTheSpinPersists) {
  PhysicsOptions p = twisting_physics();
  p.wall.mu_t = 0;
  Grains g;
  g.add(0, {0.5, 0.5, kRadius - 1e-7}, kRadius, kDensity);
  g.w[0] = {0, 0, kSpin};
  Simulation sim(g, testing::wide_box(1.0), p);
  sim.run(2000);
  EXPECT_EQ(sim.grains().w[0].z(), kSpin);
}

}  // namespace
}  // namespace granmem
