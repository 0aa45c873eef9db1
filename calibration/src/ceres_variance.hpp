#pragma once

#include <ceres/ceres.h>

#include <vector>

namespace granmem {

// The variances of scalar parameters of a solved problem, from Ceres' covariance (dense
// SVD, so that a parameter at a bound or a flat direction gives a number, not a failure);
// NaN where it cannot be computed.
inline std::vector<double> parameter_variances(ceres::Problem& problem,
                                               const std::vector<double*>& parameters) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (double* p : parameters)
    blocks.push_back({p, p});
  std::vector<double> variance(parameters.size(), std::nan(""));
  if (covariance.Compute(blocks, &problem)) {
    for (std::size_t k = 0; k < parameters.size(); ++k)
      covariance.GetCovarianceBlock(parameters[k], parameters[k], &variance[k]);
  }
  return variance;
}

}  // namespace granmem
