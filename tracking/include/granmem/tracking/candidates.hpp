#pragma once

#include <Eigen/Core>
#include <vector>

#include "granmem/tracking/holed_sphere.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {

struct CandidateOptions {
  // Grain diameter along each axis in voxels (differs along z when slices are coarser).
  Eigen::Vector3d diameter = Eigen::Vector3d::Constant(12);
  double min_response = 0.5;     // of the smoothed grain fraction, 0..1
  double min_separation = 0.65;  // of a diameter: touching grains are ~1 apart, pores nearer
};

// Where grains may be, from a normalised scan (see illumination.hpp): the grain fraction,
// binned (six bins or more per diameter: less memory and work, neighbours still apart),
// averaged over a ball of 0.8 radius, peaks at every grain's centre, the hole
// notwithstanding. Peaks above `min_response` closer than `min_separation` to a stronger
// one are dropped. With `found` (grains already located, physical coordinates with
// `voxel_size`), their model is subtracted first: what is left are the grains they hid.
// Peaks within half a diameter of a found grain (what its fit leaves, not a grain) are
// dropped before the separation is applied, so that they hide nothing; so are peaks at
// `tried` (within a quarter diameter; physical): places whose fit found less contrast than
// a grain's, such as the dark blur of a small pore between grains, stronger than theirs.
// Returns centres in voxel coordinates, to about a voxel.
std::vector<Eigen::Vector3d> find_candidates(
    const Stack& normalized, const CandidateOptions& options,
    const std::vector<HoledSphere>* found = nullptr,
    const Eigen::Vector3d& voxel_size = Eigen::Vector3d::Ones(),
    const std::vector<Eigen::Vector3d>* tried = nullptr);

}  // namespace granmem
