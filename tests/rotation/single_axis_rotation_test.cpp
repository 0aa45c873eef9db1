#include "granmem/rotation/single_axis_rotation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace granmem {
namespace {

TEST(SingleAxisRotation, PerpendicularAxesAreNinetyDegrees) {
  EXPECT_DOUBLE_EQ(single_axis_angle({1, 0, 0}, {0, 3, 0}), M_PI / 2);
}

}  // namespace
}  // namespace granmem
