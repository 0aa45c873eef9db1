#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include <fstream>

#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

class Cli : public GranmemTest {};

TEST_F(Cli, VersionNamesTheReleaseAndTheCommitAndExitsZero) {
  const RunResult r = granmem_ok({"--version"});
  EXPECT_EQ(r.out.rfind("granmem 0.", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("(commit "), std::string::npos) << r.out;
}

// As Unix tools do: 2 for a command line granmem cannot parse, 1 for a failed job.
TEST_F(Cli, UsageErrorsExitTwo) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"simulate", "--no-such-option"},
        {"no-such-command"},
        {},
        {"simulate", "--grains"}}) {
    const RunResult r = granmem(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("granmem: error: ", 0), 0u) << r.err;
  }
  std::ofstream(in_work("not_hdf5.h5")) << "text\n";  // exists: the job itself fails
  EXPECT_EQ(granmem({"info", "not_hdf5.h5"}).exit_code, 1);
}

// Whoever made a file is recorded in it (H5MD's /h5md/author), given before or after the
// command's name; the login name when not given.
TEST_F(Cli, TheAuthorIsRecordedInTheStoresWritten) {
  std::ofstream(in_work("t.csv")) << "frame,particle,x,y,z\n0,0,1,2,3\n1,0,1,2,4\n";
  granmem_ok({"--author", "A. Lab", "import", "t.csv", "--length-unit", "mm", "--out", "a.h5"});
  EXPECT_EQ(TrajectoryReader(in_work("a.h5")).header().author, "A. Lab");
  granmem_ok({"import", "t.csv", "--length-unit", "mm", "--out", "b.h5", "--author", "B. Lab"});
  EXPECT_EQ(TrajectoryReader(in_work("b.h5")).header().author, "B. Lab");
  granmem_ok({"import", "t.csv", "--length-unit", "mm", "--out", "c.h5"});
  EXPECT_FALSE(TrajectoryReader(in_work("c.h5")).header().author.empty());
  EXPECT_NE(TrajectoryReader(in_work("c.h5")).header().author, "B. Lab");
}

}  // namespace
}  // namespace granmem::testing
