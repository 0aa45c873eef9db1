// The read-out curves from a run's store, against a run whose every displacement and
// rotation is known: three grains of diameter 5 mm moved and turned from the trained
// state (frame 0) over two read-out cycles.
#include "granmem/calibration/readout.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "checks.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

constexpr double kD = 0.005;   // m
constexpr double kTurn = 0.3;  // rad, about x: tilts the cavity (body z) axis

// Grain k ends read-out cycle 1 at (k + 1) 0.1 d along x, turned by kTurn about x (the
// first) or about z (the others: a spin about the cavity axis, unseen in the single-axis
// rotation); after cycle 2 it is (k + 1) 0.3 d away, turned no further.
Trajectories known_run() {
  Trajectories run;
  RunHeader& h = run.header;
  h.id = {1, 2, 3};
  h.radius = {kD / 2, kD / 2, kD / 2};
  h.has_axis = true;
  h.has_orientation = true;
  for (int t = 0; t < 3; ++t) {
    Frame f = Frame::unknown(h);
    f.step = t;
    for (Eigen::Index k = 0; k < 3; ++k) {
      const double shift = t == 0 ? 0 : (t == 1 ? 0.1 : 0.3) * double(k + 1) * kD;
      f.position.row(k) << 0.01 * double(k) + shift, 0.02, 0.03;
      const Eigen::Vector3d about = k == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
      const Eigen::Quaterniond q(Eigen::AngleAxisd(t == 0 ? 0.0 : kTurn, about));
      f.orientation.row(k) << q.w(), q.x(), q.y(), q.z();
      f.axis.row(k) = (q * Eigen::Vector3d::UnitZ()).transpose();
    }
    run.frames.push_back(f);
  }
  return run;
}

class Readout : public testing::TempDirTest {};

TEST_F(Readout, PointsAreTheKnownMeansFromTheTrainedState) {
  write_trajectories(path("run.h5"), known_run());
  ReadoutRun run;
  run.state = 2;
  run.trained_cycles = 100;
  run.training_amplitude = 0.01;
  run.amplitude = 0.005;
  run.store = path("run.h5");
  ReadoutOptions o;
  o.bootstrap = 4000;
  const std::vector<ReadoutPoint> p = readout_points(run, o);
  ASSERT_EQ(p.size(), 2u);
  for (const ReadoutPoint& x : p) {
    EXPECT_EQ(x.state, 2u);
    EXPECT_EQ(x.trained_cycles, 100);
    EXPECT_EQ(x.amplitude, 0.005);
    EXPECT_EQ(x.grains, 3u);
    EXPECT_NEAR(x.rot_single, kTurn / 2 / 3, 1e-12);  // one grain of three tilts
    EXPECT_NEAR(x.rot_full, kTurn / 2, 1e-12);        // every grain turns
  }
  EXPECT_EQ(p[0].cycle, 1);
  EXPECT_NEAR(p[0].dr, 0.2, 1e-12);
  EXPECT_NEAR(p[0].msd, (0.01 + 0.04 + 0.09) / 3, 1e-12);
  EXPECT_TRUE(std::isnan(p[0].reversibility));
  EXPECT_EQ(p[1].cycle, 2);
  EXPECT_NEAR(p[1].dr, 0.6, 1e-12);
  EXPECT_NEAR(p[1].reversibility, 0.4, 1e-12);  // 0.2, 0.4, 0.6 d in the second cycle
  // The bootstrap's error of a mean of n values is their spread / sqrt(n).
  const double spread = std::sqrt((0.01 + 0 + 0.01) / 3);
  EXPECT_NEAR(p[0].dr_error, spread / std::sqrt(3.0), 0.05 * spread / std::sqrt(3.0));
  EXPECT_NEAR(p[0].rot_full_error, 0, 1e-6);  // the same for every grain (to acos precision)

  const Table t = readout_table(p);
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t["amplitude_pct"].values[0], 0.5);
  EXPECT_EQ(t["training_amplitude_pct"].values[0], 1);
  EXPECT_NEAR(t["dr_d"].values[1], 0.6, 1e-12);
  EXPECT_TRUE(std::isnan(t["reversibility_d"].values[0]));
}

// validate(): the sweep's part and the motion's, each bad value its one line.
TEST(ReadoutOptions, ValidateDelegatesToTheSweepAndTheMotion) {
  ReadoutOptions o;
  o.sweep.states = {"trained.h5"};
  o.sweep.amplitudes = {0.01};
  o.sweep.dir = "readout";
  EXPECT_NO_THROW(o.validate());
  ReadoutOptions no_cycle = o;
  no_cycle.sweep.cycles = 0;
  EXPECT_EQ(testing::error_message([&] { no_cycle.validate(); }),
            "readout: at least one read-out cycle per amplitude");
  ReadoutOptions wall = o;
  wall.motion.wall_distance = -1e-3;
  EXPECT_EQ(testing::error_message([&] { readout(wall); }),
            "--wall-distance: expected a length >= 0");
}

}  // namespace
}  // namespace granmem
