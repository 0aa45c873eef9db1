// Conservation laws of the integrator and the contact law.
//
// Energy: without damping (e_n = 1) and without friction, a box of grains bouncing under
// gravity, with a lid resting on them, conserves
//   E = sum (1/2 m v^2 + 1/2 I w^2 + m g z) + sum_contacts 1/2 k_n delta^2 + 1/2 M V^2 + M g Z
// up to velocity Verlet's O((w dt)^2) error.
//
// Momentum and angular momentum: every contact applies opposite forces F, -F and torques
// tau_i, tau_j with tau_i + tau_j = -(l_i + l_j) n x F_t = -|x_i - x_j| n x F_t (the rolling
// and twisting moments are opposite), so sum (x x F + tau) = 0. Velocity Verlet's kicks then
// keep P = sum m v and L = sum (m x x v + I w) exactly, and so do its drifts (x x v does not
// change when x moves along v): free grains conserve both to rounding, whatever the
// friction. This checks every lever arm and sign of the torques, l_j on unequal grains
// included.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kDensity;
using testing::kGravity;
using testing::kRadius;

double total_energy(const Simulation& sim) {
  const Grains& g = sim.grains();
  const PhysicsOptions& p = sim.physics();
  const Container& c = sim.container();
  const double k = p.contact.k_n;
  double e = sim.kinetic_energy();
  for (std::size_t i = 0; i < g.size(); ++i) {
    e += g.mass[i] * p.gravity * g.x[i].z();
    for (std::size_t j = i + 1; j < g.size(); ++j) {
      const double overlap = g.radius[i] + g.radius[j] - (g.x[i] - g.x[j]).norm();
      if (overlap > 0) e += 0.5 * k * overlap * overlap;
    }
    for (int w = 0; w < (c.lid.present ? kWallCount : kWallCount - 1); ++w) {
      const Container::Plane plane = c.plane(static_cast<Wall>(w));
      const double overlap = g.radius[i] - (plane.normal.dot(g.x[i]) - plane.offset);
      if (overlap > 0) e += 0.5 * k * overlap * overlap;
    }
  }
  if (c.lid.present) e += c.lid.mass * p.gravity * c.lid.z;  // its kinetic energy is counted above
  return e;
}

TEST(Conservation, EnergyOfElasticFrictionlessGrainsInABoxWithALid) {
  PhysicsOptions p;
  p.gravity = kGravity;
  p.contact.restitution_n = 1;
  p.contact.restitution_t = 1;
  p.contact.mu_s = p.contact.mu_r = p.contact.mu_t = 0;
  p.wall = {0, 0, 0};
  p.dt = 5e-6;  // 60 steps per collision
  // 50 grains, radii +-10%, on a loose lattice in a 3 cm box, moving at ~0.3 m/s.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Grains g;
  for (int k = 0; g.size() < 50; ++k) {
    const Eigen::Vector3d site(0.004 + 0.0065 * (k % 4), 0.004 + 0.0065 * ((k / 4) % 4),
                               0.004 + 0.0065 * (k / 16));
    g.add(k, site, kRadius * (1 + 0.1 * u(rng)), kDensity);
    g.v.back() = 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    g.w.back() = 50 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  }
  Container c = testing::wide_box(0.03);
  c.lid.present = true;
  c.lid.mass = 0.005;
  c.lid.z = 0.03;
  Simulation sim(g, c, p);
  const double e0 = total_energy(sim);
  double worst = 0;
  int lid_touches = 0, floor_touches = 0;
  for (int block = 0; block < 100; ++block) {
    sim.run(100);
    worst = std::max(worst, std::abs(total_energy(sim) - e0));
    lid_touches += sim.wall_loads().contacts[int(Wall::lid)];
    floor_touches += sim.wall_loads().contacts[int(Wall::floor)];
  }
  EXPECT_GT(lid_touches, 0) << "the test should exercise the lid";
  EXPECT_GT(floor_touches, 0);
  EXPECT_LT(worst, 2e-4 * e0) << "largest energy drift " << worst / e0;
  RecordProperty("relative_energy_drift", testing::number(worst / e0));
}

Eigen::Vector3d momentum(const Grains& g) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < g.size(); ++i)
    p += g.mass[i] * g.v[i];
  return p;
}
// About `origin`; `scale` gets the sum of the terms' norms, the size of rounding errors.
Eigen::Vector3d angular_momentum(const Grains& g, const Eigen::Vector3d& origin, double* scale) {
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  *scale = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d orbital = g.mass[i] * (g.x[i] - origin).cross(g.v[i]);
    const Eigen::Vector3d spin = g.w[i] / g.inv_inertia[i];
    l += orbital + spin;
    *scale += orbital.norm() + spin.norm();
  }
  return l;
}

// Strong friction in every mode, so that all torques are large.
PhysicsOptions frictional_free_space() {
  PhysicsOptions p;
  p.gravity = 0;
  p.contact.mu_s = 0.5;
  p.contact.mu_r = 0.2;
  p.contact.mu_t = 0.3;
  p.contact.restitution_n = 0.3;
  return p;
}

TEST(Conservation, MomentumAndAngularMomentumInAnObliqueCollisionOfUnequalGrains) {
  PhysicsOptions p = frictional_free_space();
  p.dt = 1e-6;
  Grains g;
  g.add(0, {0.5, 0.5, 0.5}, kRadius, kDensity);
  g.add(1, {0.5 + 1.7 * kRadius + 1e-6, 0.5 + 0.4 * kRadius, 0.5 + 0.2 * kRadius}, 0.7 * kRadius,
        2 * kDensity);
  g.v[0] = {0.2, 0.05, -0.03};
  g.v[1] = {-0.3, 0.1, 0.02};
  g.w[0] = {40, -30, 80};
  g.w[1] = {-100, 20, 60};
  Simulation sim(g, testing::wide_box(1.0), p);
  const Eigen::Vector3d origin(0.5, 0.5, 0.5);
  double scale = 0;
  const Eigen::Vector3d p0 = momentum(sim.grains()),
                        l0 = angular_momentum(sim.grains(), origin, &scale);
  int in_contact = 0;
  double worst_l = 0, worst_p = 0;
  for (int s = 0; s < 2000; ++s) {
    sim.step();
    in_contact += sim.contact_count() > 0;
    double sc = 0;
    worst_l = std::max(worst_l, (angular_momentum(sim.grains(), origin, &sc) - l0).norm() / sc);
    worst_p = std::max(worst_p, (momentum(sim.grains()) - p0).norm() / p0.norm());
  }
  EXPECT_GT(in_contact, 100);
  // Rounding: positions near 0.5 m lose ~1e-16 m a step against levers of ~5 mm.
  EXPECT_LT(worst_l, 1e-10);
  EXPECT_LT(worst_p, 1e-14);
  // The collision did exchange angular momentum between spin and orbit.
  EXPECT_GT((sim.grains().w[0] - g.w[0]).norm(), 1.0);
}

TEST(Conservation, MomentumAndAngularMomentumOfAFrictionalClusterInFreeSpace) {
  Grains g = testing::lattice_cluster(3, 3, 3, 0.995, 11);
  for (auto& x : g.x)
    x += Eigen::Vector3d(0.5, 0.5, 0.5);
  Simulation sim(g, testing::wide_box(1.0), frictional_free_space());
  const Eigen::Vector3d origin(0.51, 0.51, 0.51);
  double scale = 0;
  const Eigen::Vector3d l0 = angular_momentum(sim.grains(), origin, &scale);
  const Eigen::Vector3d p0 = momentum(sim.grains());
  std::size_t contacts = 0;
  for (int s = 0; s < 400; ++s) {
    sim.step();
    contacts += sim.contact_count();
  }
  EXPECT_GT(contacts, 300u);
  double sc = 0;
  const Eigen::Vector3d l1 = angular_momentum(sim.grains(), origin, &sc);
  EXPECT_LT((l1 - l0).norm(), 1e-11 * std::max(sc, scale));
  EXPECT_LT((momentum(sim.grains()) - p0).norm(), 1e-13 * sim.grains().mass[0] * 0.05);
}

// One grain touching more grains than a batch of lanes holds (PairLanes::kCapacity): the
// big grain, of smallest id, owns every pair, so its sum spans several batches and, on two
// threads, two shares. Every reaction must still be added once: momentum and angular
// momentum are kept to rounding, and both thread counts give the same bits.
TEST(Conservation, MomentumOfAGrainTouchingMoreGrainsThanABatchHolds) {
  const double big = 10 * kRadius;
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  Grains g;
  g.add(0, centre, big, kDensity);
  const int shell = 2 * PairLanes::kCapacity + 7;
  std::mt19937 random(5);
  std::uniform_real_distribution<double> speed(-0.01, 0.01);
  for (int k = 0; k < shell; ++k) {
    // Fibonacci points on the sphere, each small grain overlapping the big one by 20 um.
    const double z = 1 - (2 * k + 1.0) / shell, rho = std::sqrt(1 - z * z);
    const double phi = k * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d n(rho * std::cos(phi), rho * std::sin(phi), z);
    g.add(k + 1, centre + (big + kRadius - 2e-5) * n, kRadius, kDensity);
    g.v.back() = {speed(random), speed(random), speed(random)};
    g.w.back() = {40 * speed(random), 40 * speed(random), 40 * speed(random)};
  }
  for (int a = 1; a <= shell; ++a)
    for (int b = a + 1; b <= shell; ++b)
      ASSERT_GT((g.x[a] - g.x[b]).norm(), 2 * kRadius);  // only the big grain touches
  const Eigen::Vector3d p0 = momentum(g);
  double scale = 0;
  const Eigen::Vector3d l0 = angular_momentum(g, centre, &scale);
  std::vector<Grains> after;
  for (int threads : {1, 2}) {
    Simulation sim(g, testing::wide_box(1.0), frictional_free_space());
    sim.set_threads(threads);
    for (int s = 0; s < 5; ++s) {  // a fifth of the contacts' duration: none breaks
      sim.step();
      ASSERT_EQ(sim.contact_count(), std::size_t(shell));
    }
    double sc = 0;
    EXPECT_LT((angular_momentum(sim.grains(), centre, &sc) - l0).norm(),
              1e-11 * std::max(sc, scale));
    EXPECT_LT((momentum(sim.grains()) - p0).norm(), 1e-13 * g.mass[1] * 0.01 * shell);
    after.push_back(sim.grains());
  }
  EXPECT_TRUE(testing::same_grain_state(after[0], after[1]));
}

}  // namespace
}  // namespace granmem
