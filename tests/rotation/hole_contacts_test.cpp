#include "granmem/rotation/hole_contacts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Grain 0 at the origin, hole along z; grain 1 touching it (radius 1 each, distance
// `distance`) in the direction `polar` degrees from the z axis; grain 1's hole along x.
std::vector<std::uint8_t> pair_flags(double polar_degrees, double distance,
                                     Eigen::Vector3d axis0 = Eigen::Vector3d::UnitZ()) {
  const double t = polar_degrees * kPi / 180;
  Vectors3 centre(2, 3), axis(2, 3);
  centre.row(0) << 0, 0, 0;
  centre.row(1) << distance * std::sin(t), 0, distance * std::cos(t);
  axis.row(0) = axis0.transpose();
  axis.row(1) << 1, 0, 0;
  return hole_contacts(centre, {1.0, 1.0}, axis);
}

TEST(HoleContacts, ANeighbourInTheMouthFlagsTheGrain) {
  // Along the axis: grain 0 flagged; for grain 1 the contact is across its x-axis hole.
  EXPECT_EQ(pair_flags(0, 2.0), (std::vector<std::uint8_t>{1, 0}));
  // Either end of the hole (the axis is a line).
  EXPECT_EQ(pair_flags(180, 2.0), (std::vector<std::uint8_t>{1, 0}));
}

TEST(HoleContacts, TheMouthsHalfAngleIsAsinOfTheHoleFraction) {
  const double half_angle = std::asin(0.3) * 180 / kPi;  // 17.46 deg
  EXPECT_EQ(pair_flags(half_angle - 0.2, 2.0)[0], 1);
  EXPECT_EQ(pair_flags(half_angle + 0.2, 2.0)[0], 0);
  EXPECT_EQ(pair_flags(180 - half_angle + 0.2, 2.0)[0], 1);
}

TEST(HoleContacts, OnlyTouchingNeighboursWithinTheGap) {
  EXPECT_EQ(pair_flags(5, 2.0 * 1.049)[0], 1);  // gap 0.05 of the radii's sum
  EXPECT_EQ(pair_flags(5, 2.0 * 1.051)[0], 0);
  // A neighbour across the hole's axis touching the rim: not in the mouth.
  EXPECT_EQ(pair_flags(90, 2.0)[0], 0);
}

TEST(HoleContacts, GrainsOfUnequalRadii) {
  Vectors3 centre(2, 3), axis(2, 3);
  centre << 0, 0, 0, 0, 0, 2.9;  // radii 1 and 2: touching at 3, within the gap at 2.9
  axis << 0, 0, 1, 0, 0, 1;
  EXPECT_EQ(hole_contacts(centre, {1.0, 2.0}, axis), (std::vector<std::uint8_t>{1, 1}));
  centre(1, 2) = 3.2;
  EXPECT_EQ(hole_contacts(centre, {1.0, 2.0}, axis), (std::vector<std::uint8_t>{0, 0}));
}

TEST(HoleContacts, NoAxisNoFlag) {
  EXPECT_EQ(pair_flags(0, 2.0, Eigen::Vector3d::Constant(kNaN))[0], 0);
  EXPECT_EQ(pair_flags(0, 2.0, Eigen::Vector3d::Zero())[0], 0);
}

TEST(HoleContacts, MismatchedInputIsAnError) {
  Vectors3 centre(2, 3), axis(1, 3);
  centre.setZero();
  axis.setZero();
  EXPECT_THROW(hole_contacts(centre, {1.0, 1.0}, axis), Error);
  HoleContactOptions o;
  o.hole_fraction = 1.2;
  Vectors3 axis2(2, 3);
  axis2.setZero();
  EXPECT_THROW(hole_contacts(centre, {1.0, 1.0}, axis2, o), Error);
}

}  // namespace
}  // namespace granmem
