#include "granmem/rotation/full_rotation.hpp"

#include <cmath>
#include <limits>

namespace granmem {

double full_rotation_angle(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q2) {
  if (!q1.coeffs().allFinite() || !q2.coeffs().allFinite() || q1.norm() == 0 || q2.norm() == 0) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::Quaterniond r = q2.normalized() * q1.normalized().conjugate();
  // q and -q are the same rotation: |w| picks the angle in [0, pi].
  return 2.0 * std::atan2(r.vec().norm(), std::abs(r.w()));
}

double full_rotation_angle(const Eigen::Matrix3d& p1, const Eigen::Matrix3d& p2) {
  if (!p1.allFinite() || !p2.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix3d r = p2 * p1.transpose();
  // Via the quaternion of R rather than arccos of the trace, for precision at small angles.
  return full_rotation_angle(Eigen::Quaterniond::Identity(), Eigen::Quaterniond(r));
}

Eigen::Vector3d cavity_axis(const Eigen::Quaterniond& orientation) {
  if (!orientation.coeffs().allFinite() || orientation.norm() == 0) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return orientation.normalized() * Eigen::Vector3d::UnitZ();
}

}  // namespace granmem
