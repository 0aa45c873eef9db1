#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace granmem {

// The covariance of a least-squares fit's parameters at its minimum x, from the cost's
// curvature (Gauss-Newton: sigma^2 (J^T J)^-1, sigma^2 the residual variance). `f` is a
// TinySolver function (residuals and column-major Jacobian). None when J^T J is singular or
// there are no more residuals than parameters. It counts white noise only.
template <class Function, class Parameters>
std::optional<Eigen::Matrix<double, Parameters::RowsAtCompileTime, Parameters::RowsAtCompileTime>>
parameter_covariance(const Function& f, const Parameters& x) {
  constexpr int p = Parameters::RowsAtCompileTime;
  using Matrix = Eigen::Matrix<double, p, p>;
  const int n = f.NumResiduals();
  if (n <= p) return std::nullopt;
  Eigen::VectorXd r(n);
  Eigen::Matrix<double, Eigen::Dynamic, p> J(n, p);
  f(x.data(), r.data(), J.data());
  const Matrix jtj = J.transpose() * J;
  const Eigen::LDLT<Matrix> ldlt(jtj);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const double variance = r.squaredNorm() / double(n - p);
  return Matrix(variance * ldlt.solve(Matrix::Identity()));
}

// The standard error of an axis fitted as two tangent coordinates (parameters `first` and
// `first + 1`) around a unit axis0, given the parameters' covariance: the larger semi-axis
// of the tangent coordinates' error ellipse over |axis0 + t|, their lever arm.
template <class Covariance>
double axis_standard_error(const Covariance& covariance, int first, double lever) {
  const Eigen::Matrix2d tangent = covariance.template block<2, 2>(first, first);
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(tangent).eigenvalues().maxCoeff();
  return std::sqrt(std::max(0.0, largest)) / lever;
}

// The same from the fit itself; NaN where its covariance is not known.
template <class Function, class Parameters>
double axis_standard_error(const Function& f, const Parameters& x, int first, double lever) {
  const auto covariance = parameter_covariance(f, x);
  return covariance ? axis_standard_error(*covariance, first, lever)
                    : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace granmem
