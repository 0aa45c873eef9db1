#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

TEST(Cli, VersionExitsZero) {
  EXPECT_EQ(std::system((std::string(GRANMEM_EXE) + " --version > /dev/null").c_str()), 0);
}
