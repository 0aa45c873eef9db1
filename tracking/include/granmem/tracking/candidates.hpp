#pragma once

#include <Eigen/Core>
#include <vector>

#include "granmem/tracking/holed_sphere.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {

struct CandidateOptions {
  // Grain diameter along each axis in voxels (differs along z when slices are coarser).
  Eigen::Vector3d diameter = Eigen::Vector3d::Constant(12);
  double min_response = 0.5;    // of the smoothed grain fraction, 0..1
  double min_separation = 0.6;  // of a diameter
};

// Where grains may be, from a normalised scan (see illumination.hpp): the grain fraction,
// binned (six bins or more per diameter: less memory and work, neighbours still apart),
// smoothed with a Gaussian of half a radius, has a maximum near every grain's centre, the
// hole notwithstanding. Maxima above `min_response` closer than `min_separation` to a
// stronger one are dropped. With `found` (grains already located, physical coordinates
// with `voxel_size`), their model is subtracted first: what is left are the grains they
// hid. Returns centres in voxel coordinates, to about half a voxel.
std::vector<Eigen::Vector3d> find_candidates(
    const Stack& normalized, const CandidateOptions& options,
    const std::vector<HoledSphere>* found = nullptr,
    const Eigen::Vector3d& voxel_size = Eigen::Vector3d::Ones());

}  // namespace granmem
