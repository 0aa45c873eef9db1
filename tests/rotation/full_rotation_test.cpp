#include "granmem/rotation/full_rotation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "checks.hpp"

namespace granmem {
namespace {

using testing::random_unit_vector;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Uniform on the rotation group: a normalised Gaussian 4-vector.
Eigen::Quaterniond random_orientation(std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  return Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
}

Eigen::Quaterniond negated(const Eigen::Quaterniond& q) {
  return Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z());
}

// The paper's formula, literally: arccos((trace R - 1) / 2) with R = P2 P1^T.
double trace_formula(const Eigen::Matrix3d& p1, const Eigen::Matrix3d& p2) {
  const double c = ((p2 * p1.transpose()).trace() - 1) / 2;
  return std::acos(std::max(-1.0, std::min(1.0, c)));
}

TEST(FullRotation, KnownRelativeRotationGivesItsAngle) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Quaterniond q1 = random_orientation(rng);
    const double phi = trial == 0 ? 0.0 : trial == 1 ? M_PI : angle(rng);
    const Eigen::Quaterniond q2 =
        Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng))) * q1;
    const double measured = full_rotation_angle(q1, q2);
    ASSERT_NEAR(measured, phi, 1e-12) << "trial " << trial;
    ASSERT_GE(measured, 0.0);
    ASSERT_LE(measured, M_PI);
  }
}

TEST(FullRotation, RotationFromTheRightHasTheSameAngle) {
  // A rotation about a body axis (q2 = q1 dq) is conjugate to one about a lab axis, so it
  // has the same angle: the measure does not depend on the frame the turn is described in.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Quaterniond q1 = random_orientation(rng);
    const double phi = angle(rng);
    const Eigen::Quaterniond q2 =
        q1 * Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng)));
    EXPECT_NEAR(full_rotation_angle(q1, q2), phi, 1e-12);
    // Going back is the same turn.
    EXPECT_NEAR(full_rotation_angle(q2, q1), phi, 1e-12);
  }
}

TEST(FullRotation, QuaternionSignDoesNotMatter) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Quaterniond q1 = random_orientation(rng);
    const double phi = angle(rng);
    const Eigen::Quaterniond q2 =
        Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng))) * q1;
    // q and -q are the same orientation; without |w| the angle would come out 2 pi - phi.
    EXPECT_NEAR(full_rotation_angle(negated(q1), q2), phi, 1e-12);
    EXPECT_NEAR(full_rotation_angle(q1, negated(q2)), phi, 1e-12);
    EXPECT_NEAR(full_rotation_angle(negated(q1), negated(q2)), phi, 1e-12);
  }
  // Identity and its negation: the same orientation, no rotation.
  EXPECT_EQ(full_rotation_angle(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Quaterniond(-1, 0, 0, 0)),
            0.0);
}

TEST(FullRotation, UnnormalisedQuaternionsAreNormalised) {
  // (cos 30, sin 30 x) scaled by 5 is still the 60-degree turn about x.
  const Eigen::Quaterniond turn(5 * std::cos(M_PI / 6), 5 * std::sin(M_PI / 6), 0, 0);
  EXPECT_NEAR(full_rotation_angle(Eigen::Quaterniond(0.1, 0, 0, 0), turn), M_PI / 3, 1e-15);
}

TEST(FullRotation, SmallAnglesKeepFullRelativePrecision) {
  // Composing q2 = dq q1 in double leaves ~1e-16 absolute error in q2, which bounds how
  // small a turn of a random grain can be resolved; 1e-9 rad is well above it.
  std::mt19937 rng(13);
  for (double phi : {1e-7, 1e-9}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Quaterniond q1 = random_orientation(rng);
      const Eigen::Quaterniond q2 =
          Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng))) * q1;
      EXPECT_NEAR(full_rotation_angle(q1, q2), phi, 1e-6 * phi) << "phi " << phi;
    }
  }
  // From the identity, the turn is exactly representable: arccos((trace R - 1)/2) gives 0
  // for 1e-12 rad, the atan2 form the angle itself.
  const double tiny = 1e-12;
  const Eigen::Quaterniond turn(std::cos(tiny / 2), 0, std::sin(tiny / 2), 0);
  EXPECT_NEAR(full_rotation_angle(Eigen::Quaterniond::Identity(), turn), tiny, 1e-15 * tiny);
  EXPECT_NEAR(full_rotation_angle(Eigen::Matrix3d::Identity(), turn.toRotationMatrix()), tiny,
              1e-6 * tiny);
}

TEST(FullRotation, PrincipalAxesFormAgreesWithQuaternionAndTraceFormula) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> moderate(0.3, 2.8);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Quaterniond q1 = random_orientation(rng);
    const double phi = moderate(rng);
    const Eigen::Quaterniond q2 =
        Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng))) * q1;
    // The columns of the rotation matrix are the body axes seen in the lab.
    const Eigen::Matrix3d p1 = q1.toRotationMatrix(), p2 = q2.toRotationMatrix();
    const double from_axes = full_rotation_angle(p1, p2);
    EXPECT_NEAR(from_axes, full_rotation_angle(q1, q2), 1e-12);
    EXPECT_NEAR(from_axes, phi, 1e-12);
    // Away from 0 and pi, arccos of the trace is well conditioned and must agree.
    EXPECT_NEAR(from_axes, trace_formula(p1, p2), 1e-10);
  }
}

TEST(FullRotation, PrincipalAxesMayBeListedInAnyConsistentOrder) {
  // The tracked axes may come in any order and with any sign, as long as both frames use
  // the same labelling: R = (P2 S)(P1 S)^T = P2 P1^T for any signed permutation S, even a
  // reflection that makes P1 S left-handed.
  std::mt19937 rng(19);
  Eigen::Matrix3d relabel;
  relabel << 0, 0, -1,  //
      1, 0, 0,          //
      0, 1, 0;
  ASSERT_DOUBLE_EQ(relabel.determinant(), -1.0);
  std::uniform_real_distribution<double> angle(0, M_PI);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Quaterniond q1 = random_orientation(rng);
    const double phi = angle(rng);
    const Eigen::Quaterniond q2 =
        Eigen::Quaterniond(Eigen::AngleAxisd(phi, random_unit_vector(rng))) * q1;
    const Eigen::Matrix3d p1 = q1.toRotationMatrix() * relabel;
    const Eigen::Matrix3d p2 = q2.toRotationMatrix() * relabel;
    EXPECT_NEAR(full_rotation_angle(p1, p2), phi, 1e-12);
  }
}

TEST(FullRotation, ClosedFormCases) {
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  EXPECT_EQ(full_rotation_angle(identity, identity), 0.0);
  // Half turn about z: x -> -x, y -> -y.
  const Eigen::Matrix3d half_turn = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  EXPECT_NEAR(full_rotation_angle(identity, half_turn), M_PI, 1e-15);
  // Quarter turn about x: y -> z, z -> -y.
  Eigen::Matrix3d quarter;
  quarter << 1, 0, 0,  //
      0, 0, -1,        //
      0, 1, 0;
  EXPECT_NEAR(full_rotation_angle(identity, quarter), M_PI / 2, 1e-15);
  // Two quarter turns compose to a half turn; from the first to the second is a quarter.
  const Eigen::Matrix3d two_quarters = quarter * quarter;
  EXPECT_NEAR(full_rotation_angle(identity, two_quarters), M_PI, 1e-15);
  EXPECT_NEAR(full_rotation_angle(quarter, two_quarters), M_PI / 2, 1e-15);
  // The cyclic permutation of the axes is a 120-degree turn about (1,1,1): trace 0.
  Eigen::Matrix3d cyclic;  // x -> y -> z -> x
  cyclic << 0, 0, 1,       //
      1, 0, 0,             //
      0, 1, 0;
  EXPECT_NEAR(full_rotation_angle(identity, cyclic), 2 * M_PI / 3, 1e-15);
}

TEST(FullRotation, UnknownOrientationIsNaN) {
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  EXPECT_TRUE(
      std::isnan(full_rotation_angle(Eigen::Quaterniond(kNaN, kNaN, kNaN, kNaN), identity)));
  EXPECT_TRUE(std::isnan(full_rotation_angle(identity, Eigen::Quaterniond(1, kNaN, 0, 0))));
  EXPECT_TRUE(std::isnan(full_rotation_angle(identity, Eigen::Quaterniond(0, 0, 0, 0))));
  Eigen::Matrix3d unknown = Eigen::Matrix3d::Identity();
  unknown(1, 2) = kNaN;
  EXPECT_TRUE(std::isnan(full_rotation_angle(Eigen::Matrix3d::Identity(), unknown)));
  EXPECT_TRUE(std::isnan(full_rotation_angle(unknown, Eigen::Matrix3d::Identity())));
}

TEST(FullRotation, CavityAxisIsTheBodyZAxis) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Quaterniond q = random_orientation(rng);
    const Eigen::Vector3d axis = cavity_axis(q);
    // Third column of the rotation matrix: where the body z axis points in the lab.
    EXPECT_LT((axis - q.toRotationMatrix().col(2)).norm(), 1e-14);
    // The same grain described by -q, or by an unnormalised quaternion, has the same axis.
    EXPECT_LT((cavity_axis(negated(q)) - axis).norm(), 1e-14);
    const Eigen::Quaterniond scaled(3 * q.w(), 3 * q.x(), 3 * q.y(), 3 * q.z());
    EXPECT_LT((cavity_axis(scaled) - axis).norm(), 1e-14);
  }
  // Quarter turn about +x takes z to -y; about +y takes z to +x; about z leaves z.
  const double h = std::sqrt(0.5);
  EXPECT_LT((cavity_axis(Eigen::Quaterniond(h, h, 0, 0)) - Eigen::Vector3d(0, -1, 0)).norm(),
            1e-14);
  EXPECT_LT((cavity_axis(Eigen::Quaterniond(h, 0, h, 0)) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-14);
  EXPECT_LT((cavity_axis(Eigen::Quaterniond(h, 0, 0, h)) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-14);
  EXPECT_TRUE(cavity_axis(Eigen::Quaterniond(kNaN, 0, 0, 0)).array().isNaN().all());
  EXPECT_TRUE(cavity_axis(Eigen::Quaterniond(0, 0, 0, 0)).array().isNaN().all());
}

}  // namespace
}  // namespace granmem
