#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include <fstream>

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

}  // namespace
}  // namespace granmem::testing
