#pragma once

namespace granmem {

// The image of a disk blurred by a 2D Gaussian: the share of a unit-width Gaussian, centred
// x from the centre of a disk of radius y (both in the Gaussian's widths), that lies inside
// the disk, P(x, y) = 1 - Q1(x, y) (Marcum's Q function), with dP/dx and dP/dy. A
// cylinder's cross-section seen through a blur is this; a step's profile Phi(y - x) is
// its limit only when y >> 1: a hole 1.2 voxels wide under a blur of 0.8 voxel reads 0.71
// on its axis, not Phi(1.5) = 0.93. Interpolated bilinearly in a table made once
// (|error| < 1e-4), the derivatives being the interpolant's; for y beyond the table (a
// hole 16 blur widths wide), the step's profile corrected for the edge's curvature.
struct DiskFraction {
  double value, d_x, d_y;
};
DiskFraction blurred_disk(double x, double y);

}  // namespace granmem
