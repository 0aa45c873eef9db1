#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>

#include "granmem/core/trajectory_store.hpp"

namespace granmem {

// What a run's scans say about their own errors: the root mean square of locate's
// per-grain standard errors (carried by track into the store) over every frame. The RMS,
// because an error adds its mean square to a measured displacement or rotation.
struct ScanErrors {
  // Of the centres along x, y, z, in the run's length unit; NaN where the store has none.
  Eigen::Vector3d position = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Of the hole axes' direction, rad; NaN where the store has none.
  double axis = std::numeric_limits<double>::quiet_NaN();
  std::size_t positions = 0, axes = 0;  // the grains-in-frames averaged over
};

ScanErrors scan_errors(const TrajectoryReader& run);

}  // namespace granmem
