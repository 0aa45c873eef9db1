#include "granmem/core/option_values.hpp"

#include <gtest/gtest.h>

#include <string>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_int_range(text, "--window");
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted " << text;
  return "";
}

TEST(OptionValues, FrameRangesAreWholeNumbers) {
  EXPECT_EQ(parse_int_range("491:500", "--window"),
            (std::pair<std::int64_t, std::int64_t>{491, 500}));
  EXPECT_EQ(parse_int_range("-3:0", "--window"), (std::pair<std::int64_t, std::int64_t>{-3, 0}));
  EXPECT_NE(error_of("1.5:3").find("expected whole frame numbers"), std::string::npos);
  // Found by fuzz_option_values: a frame beyond any 64-bit label was cast to one (undefined
  // behaviour); labels beyond 2^53, which a double cannot hold exactly, are refused too.
  EXPECT_NE(error_of("2:8.8e60").find("expected whole frame numbers"), std::string::npos);
  EXPECT_NE(error_of("-1e300:2").find("expected whole frame numbers"), std::string::npos);
  EXPECT_NE(error_of("0:9007199254740994").find("expected whole frame numbers"), std::string::npos);
  EXPECT_EQ(parse_int_range("0:9007199254740992", "--window").second, 9007199254740992);
}

}  // namespace
}  // namespace granmem
