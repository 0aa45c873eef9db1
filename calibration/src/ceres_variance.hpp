#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <vector>

namespace granmem {

// The covariance matrix of scalar parameters of a solved problem (dense SVD, as below);
// NaN where it cannot be computed.
inline Eigen::MatrixXd parameter_covariance(ceres::Problem& problem,
                                            const std::vector<double*>& parameters) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (std::size_t i = 0; i < parameters.size(); ++i)
    for (std::size_t j = i; j < parameters.size(); ++j)
      blocks.push_back({parameters[i], parameters[j]});
  const Eigen::Index n = Eigen::Index(parameters.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Constant(n, n, std::nan(""));
  if (covariance.Compute(blocks, &problem)) {
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = i; j < n; ++j) {
        covariance.GetCovarianceBlock(parameters[std::size_t(i)], parameters[std::size_t(j)],
                                      &c(i, j));
        c(j, i) = c(i, j);
      }
  }
  return c;
}

// The variances of scalar parameters of a solved problem, from Ceres' covariance (dense
// SVD, so that a parameter at a bound or a flat direction gives a number, not a failure);
// NaN where it cannot be computed.
inline std::vector<double> parameter_variances(ceres::Problem& problem,
                                               const std::vector<double*>& parameters) {
  const Eigen::MatrixXd c = parameter_covariance(problem, parameters);
  std::vector<double> variance;
  for (Eigen::Index i = 0; i < c.rows(); ++i)
    variance.push_back(c(i, i));
  return variance;
}

}  // namespace granmem
