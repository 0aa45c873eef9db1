#include "granmem/tracking/hole_axis.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "granmem/tracking/illumination.hpp"

namespace granmem {

Eigen::Vector3d lab_hole_axis(const Stack& stack, const Eigen::Vector3d& centre, double radius,
                              const Eigen::Vector3d& vs, double within) {
  const double reach = within * radius;
  const Eigen::Array3d last(double(stack.nx - 1), double(stack.ny - 1), double(stack.nz - 1));
  const Eigen::Array3d lo = ((centre.array() - reach) / vs.array()).ceil().max(0.0);
  const Eigen::Array3d hi = ((centre.array() + reach) / vs.array()).floor().min(last);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int bright = 0;
  for (auto z = std::int64_t(lo.z()); z <= std::int64_t(hi.z()); ++z) {
    for (auto y = std::int64_t(lo.y()); y <= std::int64_t(hi.y()); ++y) {
      for (auto x = std::int64_t(lo.x()); x <= std::int64_t(hi.x()); ++x) {
        const Eigen::Vector3d d =
            Eigen::Vector3d(double(x), double(y), double(z)).cwiseProduct(vs) - centre;
        if (d.norm() > reach || fluid_fraction(stack.at(x, y, z)) < 0.5) continue;
        scatter += d * d.transpose();
        ++bright;
      }
    }
  }
  if (bright < 3) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
}

}  // namespace granmem
