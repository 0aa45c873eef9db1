#pragma once

#include <Eigen/Core>
#include <limits>

#include "granmem/tracking/grain_fit.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {

// The lab's classical hole axis, the baseline the model fit is measured against (and what
// `locate` gives without the axis fit): the eigenvector of the largest eigenvalue of the
// scatter of the hole's voxels (fluid fraction >= 0.5 in a normalised scan) within
// `within` x the radius of the centre. Physical coordinates with `voxel_size` (anisotropic
// voxels weigh as the space they sample). NaN when fewer than three voxels are bright.
Eigen::Vector3d lab_hole_axis(const Stack& normalized, const Eigen::Vector3d& centre, double radius,
                              const Eigen::Vector3d& voxel_size, double within = 0.8);

struct HoleAxisOptions {
  double within = 0.8;  // of the radius: the voxels the axis is fitted to
  int max_iterations = 30;
};

struct HoleAxisFit {
  Eigen::Vector3d axis = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double sigma = std::numeric_limits<double>::quiet_NaN();  // standard error, radians
  double blur_across = 0, blur_along_z = 0;                 // fitted, as the radius
  bool converged = false;
};

// The hole's axis refitted on the grain's inner voxels (within `within` x its radius of
// the fitted centre; `inner` as GrainWindow, neighbours' share optional), its centre and
// radius held, with a blur of its own across the slices (x, y) and along z. Why: a
// model blurred alike in every direction, fitted to a scan blurred more along z (coarse
// slices), tilts the axis by degrees: the hole's mouths and the sphere's rim are seen
// through different blurs in different directions. Inside ~0.8 R there are no mouths; the
// hole's cross-section is a disk blurred by the blur's covariance in the plane across the
// axis (exact for a cylinder), the sphere's rim blurred by the Gaussian's width along its
// normal (exact for a plane); the image is then symmetric under reflection through every
// plane holding the axis, so the fit has its minimum on the true axis. On isotropic
// scans it halves the error too (no mouth misfit). Starts from `grain`'s axis.
HoleAxisFit fit_hole_axis(const GrainWindow& inner, const GrainFit& grain,
                          const HoleAxisOptions& options = {});

}  // namespace granmem
