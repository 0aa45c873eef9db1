#pragma once

#include <Eigen/Core>

#include "granmem/tracking/stack.hpp"

namespace granmem {

// The lab's classical hole axis, the baseline the model fit is measured against (and what
// `locate` gives without the axis fit): the eigenvector of the largest eigenvalue of the
// scatter of the hole's voxels (fluid fraction >= 0.5 in a normalised scan) within
// `within` x the radius of the centre. Physical coordinates with `voxel_size` (anisotropic
// voxels weigh as the space they sample). NaN when fewer than three voxels are bright.
Eigen::Vector3d lab_hole_axis(const Stack& normalized, const Eigen::Vector3d& centre, double radius,
                              const Eigen::Vector3d& voxel_size, double within = 0.8);

}  // namespace granmem
