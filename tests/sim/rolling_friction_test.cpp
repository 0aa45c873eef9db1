// Rolling friction: a sphere rolling without slipping on the floor decelerates uniformly.
//
// Derivation. On the floor the contact's lever is l_i = d, the centre's height (R minus the
// overlap m g / k_n), and l_ij = 2 d. Once the rolling slider is saturated it exerts the
// moment M = mu_r beta l_ij |F_n| = 2 mu_r beta d m g against the rolling; the sliding contact
// holds the contact point still (v = d w) with a horizontal force F. With the sliding force's
// torque -d n x F on the grain,
//   m dv/dt = F,   I dw/dt = -d F - M,   dv/dt = d dw/dt
// so that dv/dt = -d M / (I + m d^2) = -M / (I/d + m d), that is
//   a = -2 mu_r beta g d^2 / (2/5 R^2 + d^2)   (= -(10/7) mu_r beta g for d = R).
// The sliding contact needs |F| = m |a| < mu_s m g to stick: true for the values below.
#include <gtest/gtest.h>

#include <cmath>

#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kDensity;
using testing::kGravity;
using testing::kRadius;

struct Rolling {
  double speed_early, speed_late, t_early, t_late;
  double slip_late;  // |v - d w x n|, the contact point's speed at t_late
};

// A sphere rolling on the floor along the horizontal direction `dir`, starting at speed v0.
Simulation rolling_sphere(const Eigen::Vector3d& dir, double v0, double mu_r, double* d_out) {
  PhysicsOptions p;
  p.gravity = kGravity;
  p.wall = {0.3, mu_r, 0};
  Grains g;
  g.add(0, {0.5, 0.5, 0}, kRadius, kDensity);
  const double d = kRadius - testing::resting_overlap(g.mass[0], p);
  g.x[0].z() = d;
  g.v[0] = v0 * dir;
  g.w[0] = Eigen::Vector3d::UnitZ().cross(dir) * (v0 / d);  // rolling without slipping
  *d_out = d;
  return Simulation(g, testing::wide_box(1.0), p);
}

TEST(RollingFriction, RollingSphereDeceleratesAtThePredictedRate) {
  const double v0 = 0.1, mu_r = 0.1, beta = ContactParameters{}.beta;
  for (const Eigen::Vector3d& dir :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(std::cos(0.5), std::sin(0.5), 0)}) {
    double d = 0;
    Simulation sim = rolling_sphere(dir, v0, mu_r, &d);
    const double dt = sim.physics().dt;
    const double expected = -2 * mu_r * beta * kGravity * d * d / (0.4 * kRadius * kRadius + d * d);
    // After the sliding spring's start-up transient (~1 ms), before the sphere stops.
    const double t1 = 0.02, t2 = 0.1;
    sim.run(std::llround(t1 / dt));
    const double v1 = sim.grains().v[0].dot(dir);
    sim.run(std::llround((t2 - t1) / dt));
    const Grains& g = sim.grains();
    const double v2 = g.v[0].dot(dir);
    const double measured = (v2 - v1) / (t2 - t1);
    EXPECT_NEAR(measured, expected, 0.02 * std::abs(expected)) << "direction " << dir.transpose();
    // Still rolling without slipping, and straight.
    const Eigen::Vector3d contact_velocity = g.v[0] - d * g.w[0].cross(Eigen::Vector3d::UnitZ());
    EXPECT_LT(contact_velocity.norm(), 1e-3 * v0);
    EXPECT_NEAR((g.v[0] - v2 * dir).norm(), 0, 1e-6 * v0);
    RecordProperty("deceleration_measured", testing::number(measured));
    RecordProperty("deceleration_expected", testing::number(expected));

    // It stops near v0 / |a| and stays stopped (the rolling spring holds it).
    sim.run(std::llround((1.2 * v0 / std::abs(expected) - t2) / dt));
    EXPECT_LT(sim.grains().v[0].norm(), 2e-3 * v0);
    EXPECT_LT(sim.grains().w[0].norm() * d, 2e-3 * v0);
  }
}

// Without rolling friction, a rolling sphere keeps its speed.
TEST(RollingFriction, WithoutRollingFrictionTheSphereRollsOn) {
  double d = 0;
  Simulation sim = rolling_sphere({0, 1, 0}, 0.1, 0, &d);
  sim.run(4000);
  EXPECT_NEAR(sim.grains().v[0].y(), 0.1, 1e-6);
  EXPECT_NEAR(sim.grains().w[0].x() * d, -0.1, 1e-6);
}

}  // namespace
}  // namespace granmem
