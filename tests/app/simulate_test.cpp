// `granmem simulate` end to end: a tiny packing deposited, cycled, written, resumed and
// analysed by the same program; bad configurations refused before anything is written.
#include <gtest/gtest.h>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;

// 60 grains in a 2 cm box: a few seconds in all.
const std::vector<std::string> kTiny = {"simulate",    "--grains", "60",       "--box", "2cm",
                                        "--amplitude", "1%",       "--period", "20ms"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

TEST_F(GranmemTest, SimulateWritesFramesTheAnalysisReads) {
  const RunResult r = granmem_ok(with(kTiny, {"--cycles", "2", "--out", "run.h5"}));
  EXPECT_NE(r.err.find("settled: packing fraction"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("particle-steps/s"), std::string::npos) << r.err;  // progress
  const TrajectoryReader run(in_work("run.h5"));
  EXPECT_EQ(run.frame_count(), 3u);  // the prepared packing and two cycles
  EXPECT_EQ(run.steps(), (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(run.header().grain_count(), 60u);
  EXPECT_TRUE(run.header().has_axis);
  EXPECT_TRUE(run.header().has_orientation);
  EXPECT_EQ(run.header().length_unit, "m");
  for (const char* o : {"wall_force", "wall_force_full_compression", "lid_height",
                        "packing_fraction", "kinetic_energy", "contacts_per_grain"}) {
    ASSERT_EQ(run.observables().count(o), 1u) << o;
    EXPECT_EQ(run.observables().at(o).value.size(), 3u) << o;
  }
  // The lid stays on the packing; the packing fraction is that of a loose random packing.
  const auto& phi = run.observables().at("packing_fraction").value;
  for (double p : phi)
    EXPECT_GT(p, 0.45);
  EXPECT_TRUE(fs::exists(in_work("run.checkpoint.h5")));
  EXPECT_TRUE(fs::exists(in_work("run.xmf")));

  granmem_ok({"analyze", "run.h5", "--out", "a"});
  const Table per_frame = read_columns(in_work("a") / "per_frame.csv", {"frame", "n", "mean_dr"});
  EXPECT_EQ(per_frame["frame"].values, (std::vector<double>{1, 2}));
  EXPECT_EQ(per_frame["n"].values, (std::vector<double>{60, 60}));
  for (double dr : per_frame["mean_dr"].values)
    EXPECT_GT(dr, 0);
  // Simulated runs have orientations: the full rotation comes too.
  EXPECT_TRUE(fs::exists(in_work("a") / "pdf_theta_full_deg.csv"));
}

// The lid presses with the paper's 436 Pa (1 kg on 15 x 15 cm) in any box, unless told
// otherwise as a pressure or as a mass (not both); the quasi-static period follows the
// pressure as 1 / sqrt(P).
TEST_F(GranmemTest, SimulateLidPressesWithThePapersPressureInAnyBox) {
  auto lid_mass = [&](const std::string& checkpoint) {
    return read_checkpoint(in_work(checkpoint)).container().lid.mass;
  };
  const double area = 0.02 * 0.02, g = 9.81;
  const RunResult paper = granmem_ok(with(kTiny, {"--cycles", "1", "--out", "paper.h5"}));
  EXPECT_NEAR(lid_mass("paper.checkpoint.h5") * g / area, 436.0, 1e-9);
  EXPECT_NE(paper.err.find("436 Pa"), std::string::npos) << paper.err;
  granmem_ok(with(kTiny, {"--cycles", "1", "--lid-pressure", "1.5kPa", "--out", "p.h5"}));
  EXPECT_NEAR(lid_mass("p.checkpoint.h5") * g / area, 1500.0, 1e-9);
  granmem_ok(with(kTiny, {"--cycles", "1", "--lid-mass", "30g", "--out", "m.h5"}));
  EXPECT_NEAR(lid_mass("m.checkpoint.h5"), 0.03, 1e-15);
  const RunResult both =
      granmem(with(kTiny, {"--lid-mass", "30g", "--lid-pressure", "1.5kPa", "--out", "b.h5"}));
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.err.find("not both"), std::string::npos) << both.err;
  EXPECT_FALSE(fs::exists(in_work("b.h5")));

  // The period for the default I = 2e-3 (5 mm grains, 1 % of the box): the paper's
  // 0.182727 s at its pressure (half that of I = 1e-3), half that at 4x the pressure.
  auto period = [&](const std::string& pressure) {
    const RunResult r = granmem_ok({"simulate", "--grains", "60", "--box", "2cm", "--cycles", "1",
                                    "--lid-pressure", pressure, "--out", pressure + ".h5"});
    const auto at = r.err.find("period ");
    return at == std::string::npos ? -1.0 : std::stod(r.err.substr(at + 7));
  };
  EXPECT_NEAR(period("436Pa"), 0.365454 / 2, 1e-6);
  EXPECT_NEAR(period("1744Pa"), 0.365454 / 4, 1e-6);
}

TEST_F(GranmemTest, SimulateResumedGivesTheSameRun) {
  granmem_ok(with(kTiny, {"--cycles", "2", "--out", "whole.h5"}));
  granmem_ok(with(kTiny, {"--cycles", "1", "--out", "split.h5"}));
  granmem_ok({"simulate", "--resume", "split.checkpoint.h5", "--cycles", "2"});
  const Trajectories a = read_trajectories(in_work("whole.h5"));
  const Trajectories b = read_trajectories(in_work("split.h5"));
  ASSERT_EQ(a.frames.size(), 3u);
  ASSERT_EQ(b.frames.size(), 3u);
  for (std::size_t t = 0; t < 3; ++t) {
    EXPECT_EQ(a.frames[t].position, b.frames[t].position) << "frame " << t;
    EXPECT_EQ(a.frames[t].orientation, b.frames[t].orientation) << "frame " << t;
  }
  EXPECT_EQ(a.observables.at("wall_force").value, b.observables.at("wall_force").value);
}

TEST_F(GranmemTest, SimulateStartsANewProtocolFromATrainedPacking) {
  granmem_ok(with(kTiny, {"--cycles", "1", "--out", "trained.h5"}));
  // A read-out at another amplitude, from the trained state, into its own outputs.
  granmem_ok({"simulate", "--start-from", "trained.checkpoint.h5", "--amplitude", "0.5%",
              "--period", "20ms", "--cycles", "1", "--out", "readout.h5"});
  const Trajectories trained = read_trajectories(in_work("trained.h5"));
  const Trajectories readout = read_trajectories(in_work("readout.h5"));
  ASSERT_EQ(readout.frames.size(), 2u);
  // Its first frame is the trained packing exactly; then it moves on its own.
  EXPECT_EQ(readout.frames[0].position, trained.frames.back().position);
  EXPECT_EQ(readout.frames[0].orientation, trained.frames.back().orientation);
  EXPECT_NE(readout.frames[1].position, readout.frames[0].position);
  EXPECT_EQ(readout.header.parameters.at("simulate/amplitude"), "0.5%");
  EXPECT_EQ(readout.header.parameters.at("simulate/start-from"), "trained.checkpoint.h5");
  // The packing's physics are the checkpoint's: another friction is refused.
  const RunResult r = granmem({"simulate", "--start-from", "trained.checkpoint.h5", "--mu-s", "0.5",
                               "--cycles", "1", "--out", "other.h5"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--mu-s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(in_work("other.h5")));
}

TEST_F(GranmemTest, SimulateNeverOverwritesWhatItStartsFrom) {
  granmem_ok(with(kTiny, {"--cycles", "1", "--out", "run.h5"}));
  const auto before = snapshot(work());
  // The default --out (run.h5) would overwrite the trained run and its checkpoint.
  RunResult r = granmem(
      {"simulate", "--start-from", "run.checkpoint.h5", "--cycles", "1", "--period", "20ms"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("is the input --start-from"), std::string::npos) << r.err;
  // One file for two outputs.
  r = granmem(with(kTiny, {"--cycles", "1", "--out", "same.h5", "--checkpoint", "same.h5"}));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("are one file"), std::string::npos) << r.err;
  // A folder that is not there, a grain that is not there: refused before any work.
  r = granmem(with(kTiny, {"--cycles", "1", "--out", "nowhere/run2.h5"}));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
  r = granmem(with(
      kTiny, {"--cycles", "1", "--out", "run3.h5", "--track", "60", "--samples-per-cycle", "5"}));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(snapshot(work()), before);
}

TEST_F(GranmemTest, SimulateResumedKeepsItsSettings) {
  granmem_ok(with(kTiny, {"--cycles", "1", "--out", "run.h5"}));
  const RunResult r =
      granmem({"simulate", "--resume", "run.checkpoint.h5", "--cycles", "2", "--amplitude", "5%"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--amplitude"), std::string::npos) << r.err;
  granmem_ok({"simulate", "--resume", "run.checkpoint.h5", "--cycles", "2"});
  const TrajectoryReader run(in_work("run.h5"));
  EXPECT_EQ(run.frame_count(), 3u);
  // The parameters say what was run: two cycles now.
  EXPECT_EQ(run.header().parameters.at("simulate/cycles"), "2");
}

TEST_F(GranmemTest, SimulateRefusesBadConfigurationsBeforeWriting) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--k-n", "-4e6g/s^2"}, "k_n"},
      {{"--amplitude", "60%"}, "amplitude"},
      {{"--dt", "100us"}, "time step"},
      {{"--mu-s", "-0.1"}, "mu_s"},
      {{"--restitution-n", "1.5"}, "restitution_n"},
      {{"--dt", "25 furlongs"}, "--dt"},
      {{"--full-compression", "maybe"}, "--full-compression"},
      {{"--polydispersity", "1"}, "--polydispersity"},
      {{"--grains", "1e30"}, "--grains"},
      {{"--track", "3"}, "--samples-per-cycle"},
  };
  for (const auto& [bad, named] : cases) {
    const RunResult r = granmem(with(with(kTiny, {"--cycles", "1", "--out", "bad.h5"}), bad));
    EXPECT_NE(r.exit_code, 0) << bad[0];
    // Refused before the packing is made: the error is all it prints.
    ASSERT_EQ(r.err_lines().size(), 1u) << bad[0] << ": " << r.err;
    const std::string last = r.err_lines().back();
    EXPECT_EQ(last.rfind("granmem: error: ", 0), 0u) << last;
    EXPECT_NE(last.find(named), std::string::npos) << last;
    EXPECT_FALSE(fs::exists(in_work("bad.h5"))) << bad[0];
  }
  // The automatic period needs a positive inertial number.
  const RunResult r = granmem({"simulate", "--grains", "60", "--box", "2cm", "--cycles", "1",
                               "--inertial-number", "0", "--out", "bad.h5"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_NE(r.err.find("--inertial-number"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace granmem::testing
