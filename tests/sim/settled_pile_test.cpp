// A packing deposited and settled under the lid is in static equilibrium. With frictionless
// walls (grains among themselves keep the paper's friction) the walls take normal loads only:
// - the floor carries the weight of the grains and of the lid: F_floor,z = -(sum m g + M g);
// - no net horizontal force on the grains: opposite side walls take opposite loads;
// - the lid at rest carries M g: its net force (grains' push minus M g) is ~0.
// (With the default wall friction the side walls hold ~6% of the weight here, Janssen's
// effect, and the floor and lid take tangential loads: the balances then hold only for the
// sum over all walls.)
#include <gtest/gtest.h>

#include <cmath>

#include "granmem/sim/deposit.hpp"
#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

TEST(SettledPile, WallLoadsBalanceTheWeightOfGrainsAndLid) {
  DepositOptions o;
  o.grains = 300;
  o.box_side = 0.03;
  o.lid_mass = 0.04;  // ~440 Pa on 3 x 3 cm, the paper's pressure
  o.seed = 3;
  o.settling_damping = 20;   // 1/s: fast, yet not so strong that grains fall slowly
  o.settled_energy = 1e-14;  // J per grain
  PhysicsOptions p;
  p.wall = {0, 0, 0};
  DepositSummary summary;
  const Simulation sim = deposit(o, p, &summary);
  const Grains& g = sim.grains();
  const Container& c = sim.container();
  const WallLoads& loads = sim.wall_loads();
  ASSERT_EQ(g.size(), 300u);
  ASSERT_TRUE(c.lid.present);

  double weight = 0;
  for (double m : g.mass)
    weight += m * p.gravity;
  const double lid_weight = c.lid.mass * p.gravity;
  auto load = [&](Wall w) { return loads.force[int(w)]; };

  // The lid rests: it carries M g, and its net force is ~0.
  EXPECT_NEAR(load(Wall::lid).z(), lid_weight, 0.01 * lid_weight);
  EXPECT_NEAR(c.lid.force, 0, 0.01 * lid_weight);
  EXPECT_LT(std::abs(c.lid.v), 1e-4);
  EXPECT_EQ(summary.lid_height, c.lid.z);

  // Vertical balance: the floor takes everything; frictionless walls take normal loads only.
  const double floor_z = load(Wall::floor).z();
  EXPECT_NEAR(floor_z, -(weight + lid_weight), 0.01 * (weight + lid_weight));
  EXPECT_EQ(load(Wall::floor).x(), 0);
  EXPECT_EQ(load(Wall::floor).y(), 0);
  for (Wall w : {Wall::x_low, Wall::x_high, Wall::y_low, Wall::y_high}) {
    const Eigen::Vector3d n = c.plane(w).normal;
    EXPECT_EQ((load(w) - load(w).dot(n) * n).norm(), 0) << "wall " << int(w);
  }

  // Horizontal balance: opposite side walls take opposite loads.
  const double fx = load(Wall::x_low).x(), fy = load(Wall::y_low).y();
  EXPECT_LT(fx, 0);  // the packing pushes the x = 0 wall towards -x
  EXPECT_LT(fy, 0);
  EXPECT_NEAR(load(Wall::x_high).x(), -fx, 0.01 * std::abs(fx));
  EXPECT_NEAR(load(Wall::y_high).y(), -fy, 0.01 * std::abs(fy));

  // Every grain inside the box, below the lid; every wall touched.
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int w = 0; w < kWallCount; ++w) {
      const Container::Plane plane = c.plane(static_cast<Wall>(w));
      EXPECT_GT(plane.normal.dot(g.x[i]) - plane.offset, 0.9 * g.radius[i]) << "grain " << i;
    }
  }
  for (int w = 0; w < kWallCount; ++w)
    EXPECT_GT(loads.contacts[w], 0) << "wall " << w;
  RecordProperty("floor_load_over_weight", testing::number(-floor_z / (weight + lid_weight)));
  RecordProperty("x_walls", testing::number(load(Wall::x_high).x() / -fx));
  RecordProperty("y_walls", testing::number(load(Wall::y_high).y() / -fy));
  RecordProperty("lid_force_over_weight", testing::number(c.lid.force / lid_weight));
  RecordProperty("packing_fraction", testing::number(summary.packing_fraction));
  RecordProperty("settling_time", testing::number(summary.settling_time));
}

}  // namespace
}  // namespace granmem
