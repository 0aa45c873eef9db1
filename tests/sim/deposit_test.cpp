// Insertion and the in-cycle sampling schedule of the protocol.
#include <gtest/gtest.h>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

TEST(Deposit, InsertedGrainsOverlapNeitherEachOtherNorTheWalls) {
  for (double polydispersity : {0.0, 0.1}) {
    DepositOptions o;
    o.grains = 3000;
    o.box_side = 0.07;
    o.polydispersity = polydispersity;
    const Grains g = insert_grains(o, PhysicsOptions{});
    ASSERT_EQ(g.size(), 3000u);
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Eigen::Vector3d& x = g.x[i];
      const double r = g.radius[i];
      EXPECT_GE(x.x(), r);
      EXPECT_GE(x.y(), r);
      EXPECT_GE(x.z(), r);
      EXPECT_LE(x.x(), o.box_side - r);
      EXPECT_LE(x.y(), o.box_side - r);
      for (std::size_t j = i + 1; j < g.size() && j < i + 700; ++j) {  // near in the lattice
        EXPECT_GT((x - g.x[j]).norm(), r + g.radius[j]) << i << " " << j;
      }
    }
  }
}

class CyclicSamples : public testing::TempDirTest {};

TEST_F(CyclicSamples, InCycleSamplesAreExactlyAsManyAsAsked) {
  DepositOptions o;
  o.grains = 40;
  o.box_side = 0.02;
  Simulation sim = deposit(o, PhysicsOptions{});
  CyclicOptions c;
  c.drive.amplitude = 2e-4;
  c.drive.period = 130 * sim.physics().dt;  // 130 steps: 50 samples do not divide it
  c.cycles = 2;
  c.out = path("run.h5");
  c.tracked_grains = {3, 7};
  c.samples_per_cycle = 50;
  ProtocolState state;
  run_cycles(sim, c, state);
  const TrajectoryReader samples(in_cycle_path(c.out));
  EXPECT_EQ(samples.frame_count(), 100u);
  EXPECT_EQ(samples.header().grain_count(), 2u);
  // The last sample of each cycle is its last step; the end-of-cycle frame is the same state.
  const TrajectoryReader end(c.out);
  EXPECT_EQ(samples.read_frame(49).position.row(0), end.read_frame(1).position.row(3));
  EXPECT_EQ(samples.read_frame(99).position.row(0), end.read_frame(2).position.row(3));
  EXPECT_EQ(samples.read_frame(99).position.row(1), end.read_frame(2).position.row(7));
}

}  // namespace
}  // namespace granmem
