#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace granmem {

// The standard error of an axis fitted as two tangent coordinates (parameters `first` and
// `first + 1`) around a unit axis0, from the curvature of a least-squares cost at its
// minimum x (Gauss-Newton: covariance sigma^2 (J^T J)^-1, sigma^2 the residual variance):
// the larger semi-axis of the tangent coordinates' error ellipse over |axis0 + t|, their
// lever arm. `f` is a TinySolver function (residuals and column-major Jacobian). NaN when
// J^T J is singular or there are no more residuals than parameters.
template <class Function, class Parameters>
double axis_standard_error(const Function& f, const Parameters& x, int first, double lever) {
  constexpr int p = Parameters::RowsAtCompileTime;
  const int n = f.NumResiduals();
  if (n <= p) return std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd r(n);
  Eigen::Matrix<double, Eigen::Dynamic, p> J(n, p);
  f(x.data(), r.data(), J.data());
  const Eigen::Matrix<double, p, p> jtj = J.transpose() * J;
  const Eigen::LDLT<Eigen::Matrix<double, p, p>> ldlt(jtj);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double variance = r.squaredNorm() / double(n - p);
  const Eigen::Matrix<double, p, p> covariance =
      variance * ldlt.solve(Eigen::Matrix<double, p, p>::Identity());
  const Eigen::Matrix2d tangent = covariance.template block<2, 2>(first, first);
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(tangent).eigenvalues().maxCoeff();
  return std::sqrt(std::max(0.0, largest)) / lever;
}

}  // namespace granmem
