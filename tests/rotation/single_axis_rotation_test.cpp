#include "granmem/rotation/single_axis_rotation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "checks.hpp"

namespace granmem {
namespace {

using testing::random_unit_vector;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The angle between the lines along unit a and R a, R the rotation by phi about unit u:
// Rodrigues' formula gives a . R a = cos(phi) + (1 - cos(phi)) (u . a)^2 for the angle
// alpha between the vectors; the lines meet at min(alpha, pi - alpha). Evaluated in long
// double so that the reference is far more precise than the code under test.
double rodrigues_line_angle(const Eigen::Vector3d& u, double phi, const Eigen::Vector3d& a) {
  const long double ua = static_cast<long double>(u.x()) * a.x() +
                         static_cast<long double>(u.y()) * a.y() +
                         static_cast<long double>(u.z()) * a.z();
  const long double c = std::cos(static_cast<long double>(phi));
  const long double cos_alpha = std::clamp(c + (1 - c) * ua * ua, -1.0L, 1.0L);
  const long double alpha = std::acos(cos_alpha);
  return static_cast<double>(std::min(alpha, static_cast<long double>(M_PI) - alpha));
}

TEST(SingleAxisRotation, PerpendicularAxesAreNinetyDegrees) {
  EXPECT_DOUBLE_EQ(single_axis_angle({1, 0, 0}, {0, 3, 0}), M_PI / 2);
  // Exactly pi/2 (atan2(1, 0)) for perpendicular axes in any direction, not merely close.
  EXPECT_EQ(single_axis_angle({0, 0, 2}, {-5, 0, 0}), M_PI / 2);
  EXPECT_EQ(single_axis_angle({1, 1, 0}, {1, -1, 0}), M_PI / 2);
  EXPECT_EQ(single_axis_angle({0, -1, 0}, {0, 0, -7}), M_PI / 2);
}

TEST(SingleAxisRotation, RandomRotationsMatchRodriguesLineAngle) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d u = random_unit_vector(rng);
    const double phi = angle(rng);
    const Eigen::Vector3d a = random_unit_vector(rng);
    const Eigen::Vector3d rotated = Eigen::AngleAxisd(phi, u) * a;
    const double measured = single_axis_angle(a, rotated);
    const double expected = rodrigues_line_angle(u, phi, a);
    ASSERT_GE(measured, 0.0);
    ASSERT_LE(measured, M_PI / 2);
    ASSERT_NEAR(measured, expected, 1e-9) << "trial " << trial << " phi " << phi;
  }
}

TEST(SingleAxisRotation, AxisIsALineSoSignDoesNotMatter) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d a = random_unit_vector(rng);
    const Eigen::Vector3d b = Eigen::AngleAxisd(angle(rng), random_unit_vector(rng)) * a;
    const double theta = single_axis_angle(a, b);
    // Flipping either axis is an exact symmetry of |a x b| and |a . b|.
    EXPECT_EQ(single_axis_angle(-a, b), theta);
    EXPECT_EQ(single_axis_angle(a, -b), theta);
    EXPECT_EQ(single_axis_angle(-a, -b), theta);
    // And so is the order: the angle between two lines has no direction.
    EXPECT_EQ(single_axis_angle(b, a), theta);
  }
  // Antiparallel vectors are the same line: no rotation at all.
  EXPECT_EQ(single_axis_angle({0, 0, 1}, {0, 0, -1}), 0.0);
  // A 135-degree turn of the vector is a 45-degree turn of the line.
  EXPECT_NEAR(single_axis_angle({1, 0, 0}, {-1, 1, 0}), M_PI / 4, 1e-15);
}

TEST(SingleAxisRotation, LengthOfTheAxisVectorsDoesNotMatter) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> log_scale(-3, 3);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d u = random_unit_vector(rng);
    const double phi = angle(rng);
    const Eigen::Vector3d a = random_unit_vector(rng);
    const Eigen::Vector3d b = Eigen::AngleAxisd(phi, u) * a;
    const double s1 = std::pow(10.0, log_scale(rng)), s2 = std::pow(10.0, log_scale(rng));
    EXPECT_NEAR(single_axis_angle(s1 * a, s2 * b), rodrigues_line_angle(u, phi, a), 1e-9);
  }
  // 60 degrees between (1,0,0) and (1, sqrt 3, 0), whatever their lengths.
  EXPECT_NEAR(single_axis_angle({4, 0, 0}, {0.5, 0.5 * std::sqrt(3.0), 0}), M_PI / 3, 1e-15);
}

TEST(SingleAxisRotation, UnknownOrZeroAxisIsNaN) {
  const Eigen::Vector3d z(0, 0, 1);
  EXPECT_TRUE(std::isnan(single_axis_angle({kNaN, kNaN, kNaN}, z)));
  EXPECT_TRUE(std::isnan(single_axis_angle(z, {kNaN, kNaN, kNaN})));
  // One unknown component is as unknown as three.
  EXPECT_TRUE(std::isnan(single_axis_angle({1, kNaN, 0}, z)));
  EXPECT_TRUE(std::isnan(single_axis_angle(Eigen::Vector3d::Zero(), z)));
  EXPECT_TRUE(std::isnan(single_axis_angle(z, Eigen::Vector3d::Zero())));
  EXPECT_TRUE(std::isnan(single_axis_angle(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero())));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isnan(single_axis_angle({inf, 0, 0}, z)));
}

TEST(SingleAxisRotation, SmallAnglesKeepFullRelativePrecision) {
  // arccos(|a.b|) keeps only about two digits here: cos(1e-7) = 1 - 5e-15 is stored with
  // an error of ~1e-16, i.e. 2% of 1 - cos. The atan2 form keeps nearly all digits.
  std::mt19937 rng(3);
  for (double phi : {1e-7, 3e-8, 1e-9, 2.5e-6}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d a = random_unit_vector(rng);
      // Rotate about an axis perpendicular to a, so the line turns by exactly phi.
      const Eigen::Vector3d u = a.cross(random_unit_vector(rng)).normalized();
      const Eigen::Vector3d b = Eigen::AngleAxisd(phi, u) * a;
      EXPECT_NEAR(single_axis_angle(a, b), phi, 1e-6 * phi) << "phi " << phi;
    }
  }
  // In closed form: the line (1, 1e-7, 0) is atan(1e-7) from the x axis.
  EXPECT_NEAR(single_axis_angle({1, 0, 0}, {1, 1e-7, 0}), std::atan(1e-7), 1e-15 * 1e-7);
  // A tilt just short of 90 degrees: pi/2 - 1e-7 to the same relative precision.
  EXPECT_NEAR(single_axis_angle({1, 0, 0}, {1e-7, 1, 0}), M_PI / 2 - std::atan(1e-7), 1e-15);
}

}  // namespace
}  // namespace granmem
