#include "granmem/core/error.hpp"

#include <gtest/gtest.h>

#include <string>

namespace granmem {
namespace {

using namespace std::string_literals;

TEST(ErrorMessage, ControlBytesAreShownAndTheLineIsCut) {
  EXPECT_EQ(one_printable_line("t.csv line 3: 'a\x1b[2Jb'"), "t.csv line 3: 'a\\x1b[2Jb'");
  EXPECT_EQ(one_printable_line("x\0y\r\nz\x7f"s), "x\\x00y\\x0d\\x0az\\x7f");
  EXPECT_EQ(one_printable_line("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 is kept
  const std::string field(8 << 20, 'a');
  const std::string line = one_printable_line("t.csv: '" + field + "'", 100);
  EXPECT_EQ(line, "t.csv: '" + std::string(92, 'a') + "... (" + std::to_string((8 << 20) - 91) +
                      " more bytes)");
}

}  // namespace
}  // namespace granmem
