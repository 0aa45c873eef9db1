// The memory read-out's runs: each amplitude from the same trained state, the training
// amplitude continuing the training exactly, a still wall leaving the grains where they
// were, a run the same alone as in a sweep, finished runs reused, bad input refused.
#include "granmem/sim/readout_sweep.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/quasi_static.hpp"
#include "sim_checks.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
constexpr double kTraining = 0.025;       // of the box
constexpr double kInertialNumber = 1e-3;  // quasi-static (docs/QUASISTATIC.md)

Simulation small_packing(double box = 0.02) {
  DepositOptions o;
  o.grains = 40;
  o.box_side = box;
  o.lid_mass = 0.02;
  o.seed = 9;
  o.settling_damping = 20;
  o.settled_energy = 1e-11;
  return deposit(o, PhysicsOptions{});
}

// The training drive, timed as the read-out times it: the wall's peak speed is the
// quasi-static speed under the lid.
WallDrive training_drive(const Simulation& sim) {
  const Container& c = sim.container();
  const PhysicsOptions& p = sim.physics();
  const double d = 2 * median(sim.grains().radius);
  const double stress = confining_stress(
      lid_pressure(c.lid.mass, p.gravity, c.size.x(), c.size.y()), p.density, p.gravity, d);
  WallDrive drive;
  drive.amplitude = kTraining * c.size.y();
  drive.period = quasi_static_period(kInertialNumber, drive, c.size.y(), d, stress, p.density);
  return drive;
}

class ReadoutSweep : public testing::TempDirTest {
 protected:
  // Three training cycles, the state after the second kept; returns the training store.
  fs::path train() {
    Simulation sim = small_packing();
    CyclicOptions o;
    o.drive = training_drive(sim);
    o.cycles = 3;
    o.out = path("train.h5");
    o.keep_states = {2};
    ProtocolState state;
    state.settings["amplitude"] = "2.5%";  // as simulate records it
    run_cycles(sim, o, state);
    return o.out;
  }
  fs::path state() const { return kept_state_path(path("train.h5"), 2); }
  ReadoutSweepOptions sweep(std::vector<double> amplitudes, const std::string& dir) {
    ReadoutSweepOptions o;
    o.states = {state()};
    o.amplitudes = std::move(amplitudes);
    o.inertial_number = kInertialNumber;
    o.dir = path(dir);
    return o;
  }
};

void expect_same_frame(const Frame& a, const Frame& b) {
  ASSERT_EQ(a.position.rows(), b.position.rows());
  for (Eigen::Index i = 0; i < a.position.size(); ++i)
    ASSERT_TRUE(testing::same_bits(a.position.data()[i], b.position.data()[i])) << i;
  for (Eigen::Index i = 0; i < a.orientation.size(); ++i)
    ASSERT_TRUE(testing::same_bits(a.orientation.data()[i], b.orientation.data()[i])) << i;
}

TEST_F(ReadoutSweep, AtTheTrainingAmplitudeItContinuesTheTrainingBitForBit) {
  const fs::path training = train();
  const ReadoutSweepSummary s = run_readout_sweep(sweep({0.005}, "readout"));
  ASSERT_EQ(s.runs.size(), 2u);  // the training amplitude is added, in order
  EXPECT_EQ(s.runs[0].amplitude, 0.005);
  EXPECT_NEAR(s.runs[1].amplitude, kTraining, 1e-15);
  EXPECT_EQ(s.runs[1].trained_cycles, 2);
  EXPECT_NEAR(s.runs[1].training_amplitude, kTraining, 1e-15);
  const TrajectoryReader trained(training), read_out(s.runs[1].store);
  ASSERT_EQ(read_out.frame_count(), 2u);
  expect_same_frame(read_out.read_frame(0), trained.read_frame(2));
  expect_same_frame(read_out.read_frame(1), trained.read_frame(3));
}

TEST_F(ReadoutSweep, ARunIsTheSameAloneAsInASweepAndAStillWallLeavesTheGrainsWhereTheyWere) {
  train();
  ReadoutSweepOptions all = sweep({0, 0.01, kTraining}, "all");
  all.pool.parallel = 2;
  const ReadoutSweepSummary s = run_readout_sweep(all);
  ASSERT_EQ(s.runs.size(), 3u);
  ReadoutSweepOptions one = sweep({0.01}, "one");
  one.include_training_amplitude = false;
  const ReadoutSweepSummary alone = run_readout_sweep(one);
  ASSERT_EQ(alone.runs.size(), 1u);
  expect_same_frame(TrajectoryReader(alone.runs[0].store).read_frame(1),
                    TrajectoryReader(s.runs[1].store).read_frame(1));

  const TrajectoryReader still(s.runs[0].store);
  const Frame before = still.read_frame(0), after = still.read_frame(1);
  const double d = 2 * median(still.header().radius);
  // A quasi-static training leaves the packing at rest (measured: 1e-6 d on average; a
  // training at I = 1e-2 leaves it moving, 3e-3 d): a still wall keeps it there.
  const double moved = (after.position - before.position).rowwise().norm().maxCoeff();
  EXPECT_LT(moved, 1e-4 * d);
  const TrajectoryReader driven(s.runs[1].store);
  EXPECT_GT((driven.read_frame(1).position - before.position).rowwise().norm().mean(), 100 * moved);
}

TEST_F(ReadoutSweep, FinishedRunsAreReusedAndOthersRun) {
  train();
  const ReadoutSweepOptions o = sweep({0.01}, "readout");
  const ReadoutSweepSummary first = run_readout_sweep(o);
  ASSERT_EQ(first.runs.size(), 2u);
  EXPECT_FALSE(first.runs[0].reused);
  const auto written = fs::last_write_time(first.runs[0].store);
  ReadoutSweepOptions more = o;
  more.amplitudes = {0.01, 0.015};
  int reports = 0;
  const ReadoutSweepSummary second = run_readout_sweep(more, [&](const ReadoutSweepProgress& p) {
    ++reports;
    EXPECT_EQ(p.runs, 3u);
    EXPECT_EQ(p.done, 3u);  // two reused, then the new one
  });
  ASSERT_EQ(second.runs.size(), 3u);
  EXPECT_TRUE(second.runs[0].reused);
  EXPECT_FALSE(second.runs[1].reused);
  EXPECT_TRUE(second.runs[2].reused);
  EXPECT_EQ(reports, 1);
  EXPECT_EQ(fs::last_write_time(first.runs[0].store), written);
  ReadoutSweepOptions longer = o;
  longer.cycles = 2;  // other settings: run again
  EXPECT_FALSE(run_readout_sweep(longer).runs[0].reused);
}

TEST_F(ReadoutSweep, BadInputIsRefusedWithOneLine) {
  const fs::path training = train();
  auto refused = [&](ReadoutSweepOptions o, const std::string& says) {
    try {
      run_readout_sweep(o);
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  };
  refused(sweep({}, "r"), "no read-out amplitudes");
  refused(sweep({0.5}, "r"), "less than half the box");
  refused(sweep({-0.01}, "r"), "at least 0");
  ReadoutSweepOptions o = sweep({0.01}, "r");
  o.cycles = 0;
  refused(o, "at least one read-out cycle");
  o = sweep({0.01}, "r");
  o.states = {training};
  refused(o, "not a granmem checkpoint");
  o.states = {};
  refused(o, "no trained state");
  {
    Simulation other = small_packing(0.025);
    ProtocolState p;
    write_checkpoint(path("other.h5"), other, p);
    p.step_in_cycle = 5;
    write_checkpoint(path("mid.h5"), other, p);
  }
  o = sweep({0.01}, "r");
  o.states = {state(), path("other.h5")};
  refused(o, "another box");
  o.states = {path("mid.h5")};
  refused(o, "middle of a cycle");
  EXPECT_FALSE(fs::exists(path("r")));  // nothing ran, nothing written
}

// validate() alone, before any state is read: a good sweep passes; each bad setting is its
// one line, in the order the sweep checks them.
TEST(ReadoutSweepOptions, ValidateNamesWhatIsWrongBeforeAnyStateIsRead) {
  ReadoutSweepOptions o;
  o.states = {"trained.h5"};  // not read by validate
  o.amplitudes = {0.0, 0.01};
  o.dir = "readout";
  EXPECT_NO_THROW(o.validate());
  auto message = [](const ReadoutSweepOptions& bad) {
    return testing::error_message([&] { bad.validate(); });
  };
  ReadoutSweepOptions still = o;
  still.amplitudes = {0.0};
  EXPECT_EQ(message(still),
            "readout: every amplitude is 0; a sweep needs a moving wall to time its cycles");
  ReadoutSweepOptions half = o;
  half.amplitudes = {0.5};
  EXPECT_EQ(message(half),
            "readout: amplitude 50 % of the box: must be at least 0 and less than half the box");
  ReadoutSweepOptions inertial = o;
  inertial.inertial_number = 0;
  EXPECT_EQ(message(inertial), "readout: the inertial number must be positive");
  ReadoutSweepOptions no_dir = o;
  no_dir.dir.clear();
  EXPECT_EQ(message(no_dir), "readout: no output folder (--out)");
}

TEST(AmplitudeSweep, ListsAndLogSpacedRangesOfPercentages) {
  EXPECT_EQ(parse_amplitude_sweep("0%,0.5%, 1%"), (std::vector<double>{0, 0.005, 0.01}));
  const std::vector<double> a = parse_amplitude_sweep("0.05%:2.5%:12");
  ASSERT_EQ(a.size(), 12u);
  EXPECT_DOUBLE_EQ(a.front(), 0.0005);
  EXPECT_EQ(a.back(), 0.025);
  for (std::size_t k = 1; k < a.size(); ++k)
    EXPECT_NEAR(a[k] / a[k - 1], std::pow(50.0, 1.0 / 11), 1e-12);
  for (const char* bad : {"1", "0.5cm", "1%:2%", "2%:1%:5", "0%:1%:5", "1%:2%:1", "1%:2%:2.5"})
    EXPECT_THROW(parse_amplitude_sweep(bad), Error) << bad;
}

TEST(Amplitude, APercentageOfTheBoxOrALength) {
  EXPECT_DOUBLE_EQ(parse_amplitude("1%", 0.05, "--amplitude"), 5e-4);
  EXPECT_DOUBLE_EQ(parse_amplitude("0.15cm", 0.05, "--amplitude"), 1.5e-3);
  EXPECT_THROW(parse_amplitude("1", 0.05, "--amplitude"), Error);
  EXPECT_THROW(parse_amplitude("1kg", 0.05, "--amplitude"), Error);
}

}  // namespace
}  // namespace granmem
