// `granmem readout` end to end: states kept by `simulate --keep-states`, read out at a sweep
// of amplitudes; at the training amplitude the read-out is the simulated run's next cycle,
// bit for bit; a second call reuses the finished runs; bad input is refused in one line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;

// 60 grains in a 2 cm box, trained 2 cycles at 2 % (the period from a fast inertial number:
// seconds in all), the state after cycle 1 kept.
class Readout : public GranmemTest {
 protected:
  void SetUp() override {
    GranmemTest::SetUp();
    granmem_ok({"simulate", "--grains", "60", "--box", "2cm", "--amplitude", "2%",
                "--inertial-number", "1e-2", "--cycles", "2", "--keep-states", "1", "--out",
                "train.h5"});
  }
};

bool same_positions(const Frame& a, const Frame& b) {
  return a.position.size() == b.position.size() &&
         std::memcmp(a.position.data(), b.position.data(),
                     sizeof(double) * std::size_t(a.position.size())) == 0;
}

TEST_F(Readout, AtTheTrainingAmplitudeItIsTheRunsNextCycleAndFinishedRunsAreReused) {
  const std::vector<std::string> args = {"readout",      "--from",     "train_state_cycle1.h5",
                                         "--amplitudes", "0.5%,1%,3%", "--inertial-number",
                                         "1e-2",         "--out",      "ro"};
  const RunResult r = granmem_ok(args);
  EXPECT_NE(r.err.find("4/4 runs done"), std::string::npos) << r.err;  // progress
  EXPECT_NE(r.out.find("(0 runs reused)"), std::string::npos) << r.out;
  const TrajectoryReader train(in_work("train.h5")),
      at_training(in_work("ro") / "readout_train_state_cycle1_A2pct.h5");
  ASSERT_EQ(at_training.frame_count(), 2u);
  EXPECT_TRUE(same_positions(at_training.read_frame(0), train.read_frame(1)));
  EXPECT_TRUE(same_positions(at_training.read_frame(1), train.read_frame(2)));

  const Table t = read_columns(in_work("ro") / "readout.csv",
                               {"state", "trained_cycles", "amplitude_pct", "cycle", "dr_d"});
  EXPECT_EQ(t["amplitude_pct"].values, (std::vector<double>{0.5, 1, 2, 3}));
  EXPECT_EQ(t["trained_cycles"].values, (std::vector<double>{1, 1, 1, 1}));
  // The signature of the state, whose training amplitude (2 %) lies inside the sweep.
  const Table m = read_columns(
      in_work("ro") / "memory.csv",
      {"trained_cycles", "training_amplitude_pct", "dr_dip", "dr_dip_err", "rot_single_exp_below"});
  ASSERT_EQ(m.rows(), 1u);
  EXPECT_EQ(m["training_amplitude_pct"].values[0], 2);
  EXPECT_TRUE(std::isfinite(m["dr_dip"].values[0]));
  EXPECT_GT(m["dr_dip_err"].values[0], 0);
  for (double dr : t["dr_d"].values)
    EXPECT_GT(dr, 0);

  const std::string table = read_file(in_work("ro") / "readout.csv");
  const RunResult again = granmem_ok(args);
  EXPECT_NE(again.out.find("(4 runs reused)"), std::string::npos) << again.out;
  EXPECT_EQ(read_file(in_work("ro") / "readout.csv"), table);
}

// The options from a [readout] section of a TOML file, as on the command line.
TEST_F(Readout, ATomlSectionGivesItsOptions) {
  write_text(in_work("readout.toml"),
             "[readout]\nfrom = [\"train_state_cycle1.h5\"]\namplitudes = \"0.5%,3%\"\n"
             "inertial-number = 1e-2\nout = \"ro\"\n");
  const RunResult r = granmem_ok({"--config", "readout.toml", "readout"});
  EXPECT_NE(r.err.find("3/3 runs done"), std::string::npos) << r.err;
  const Table t = read_columns(in_work("ro") / "readout.csv", {"amplitude_pct"});
  EXPECT_EQ(t["amplitude_pct"].values, (std::vector<double>{0.5, 2, 3}));
}

#ifdef GRANMEM_MPIEXEC
// On 2 MPI ranks (a -DGRANMEM_MPI=ON build): the runs are shared out, and every store and
// the table are those of the single-process read-out, bit for bit.
TEST_F(Readout, OnTwoMpiRanksItWritesTheSameRunsAndTableBitForBit) {
  const std::vector<std::string> sweep = {"readout",      "--from",     "train_state_cycle1.h5",
                                          "--amplitudes", "0.5%,1%",    "--inertial-number",
                                          "1e-2",         "--parallel", "1"};
  std::vector<std::string> one = sweep, two = sweep;
  one.insert(one.end(), {"--out", "one"});
  two.insert(two.end(), {"--out", "two"});
  granmem_ok(one);
  const std::string command =
      "cd " + shell_quote(work().string()) + " && " + shell_quote(GRANMEM_MPIEXEC) +
      " --allow-run-as-root --oversubscribe -np 2 " + shell_quote(GRANMEM_EXE);
  std::string args;
  for (const std::string& a : two)
    args += " " + shell_quote(a);
  ASSERT_EQ(std::system((command + args + " > mpi.out 2> mpi.err").c_str()), 0)
      << read_file(in_work("mpi.err"));
  const std::string said = read_file(in_work("mpi.out"));
  EXPECT_EQ(said.find("read out"), said.rfind("read out")) << "rank 1 spoke too:\n" << said;
  for (const char* a : {"0.5", "1", "2"}) {
    const std::string name = std::string("readout_train_state_cycle1_A") + a + "pct.h5";
    const TrajectoryReader x(in_work("one") / name), y(in_work("two") / name);
    ASSERT_EQ(x.frame_count(), y.frame_count()) << name;
    for (std::size_t t = 0; t < x.frame_count(); ++t)
      EXPECT_TRUE(same_positions(x.read_frame(t), y.read_frame(t))) << name << " frame " << t;
  }
  EXPECT_EQ(read_file(in_work("one") / "readout.csv"), read_file(in_work("two") / "readout.csv"));
}
#endif

TEST_F(Readout, BadInputIsRefusedInOneLineBeforeAnyRun) {
  expect_clean_failure({"readout", "--from", "train.h5", "--amplitudes", "1%", "--out", "ro"},
                       {"train.h5", "not a granmem checkpoint"});
  expect_clean_failure(
      {"readout", "--from", "train_state_cycle1.h5", "--amplitudes", "60%", "--out", "ro"},
      {"60", "less than half the box"});
  expect_clean_failure(
      {"readout", "--from", "train_state_cycle1.h5", "--amplitudes", "0.1cm", "--out", "ro"},
      {"--amplitudes", "percentages"});
  expect_clean_failure(
      {"readout", "--from", "train_state_cycle1.h5", "--amplitudes", "", "--out", "ro"},
      {"no read-out amplitudes"});
}

}  // namespace
}  // namespace granmem::testing
