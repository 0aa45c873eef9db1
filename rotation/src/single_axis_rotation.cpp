#include "granmem/rotation/single_axis_rotation.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace granmem {

double single_axis_angle(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2) {
  const double n1 = a1.stableNorm(), n2 = a2.stableNorm();
  if (!(n1 > 0) || !(n2 > 0) || !std::isfinite(n1) || !std::isfinite(n2)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::Vector3d u1 = a1 / n1, u2 = a2 / n2;
  return std::atan2(u1.cross(u2).norm(), std::abs(u1.dot(u2)));
}

}  // namespace granmem
