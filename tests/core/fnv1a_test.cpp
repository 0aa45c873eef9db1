// The platform-independent digest behind run seeds and placed packings' identities: FNV-1a's
// published 64-bit test vectors, and a digest continued over pieces is the whole's.
#include <gtest/gtest.h>

#include <string>

#include "granmem/core/random.hpp"

namespace granmem {
namespace {

TEST(Fnv1a, MatchesThePublishedVectorsAndContinuesOverPieces) {
  EXPECT_EQ(fnv1a("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a("foobar", 6), 0x85944171f73967e8ull);
  EXPECT_EQ(fnv1a("bar", 3, fnv1a("foo", 3)), fnv1a("foobar", 6));
}

}  // namespace
}  // namespace granmem
