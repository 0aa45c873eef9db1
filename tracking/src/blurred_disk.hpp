#pragma once

#include <algorithm>
#include <cmath>

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

// P(x, y) of one disk (radius y) at any offsets x: what depends on y alone is found once
// (an annulus' blurred cross-section reads two disks at seven offsets, locate's axis refits
// some 10^9 times a scan).
class BlurredDisk {
 public:
  explicit BlurredDisk(double y);
  DiskFraction at(double x) const;

  // The table's steps and extent, in widths.
  static constexpr double kStep = 1.0 / 32, kMaxY = 16, kMaxX = kMaxY + 8;
  static constexpr int kNy = int(kMaxY / kStep) + 1, kNx = int(kMaxX / kStep) + 1;

 private:
  DiskFraction wide(double x) const;

  double y_;
  bool inside_table_ = false;  // y in (0, kMaxY): read from the table
  double ty_ = 0;              // y's place between the table's columns below and above it
  const float* below_ = nullptr;
  const float* above_ = nullptr;
};

inline DiskFraction BlurredDisk::at(double x) const {
  x = std::abs(x);
  if (!(x < kMaxX + kMaxY) || !(y_ > 0)) return {0, 0, 0};  // far, no hole, or not a number
  // Eight widths outside or inside the rim: Phi(-8) ~ 6e-16 from 0 or 1.
  if (x - y_ > 8) return {0, 0, 0};
  if (y_ - x > 8) return {1, 0, 0};
  if (!inside_table_) return wide(x);
  if (x >= kMaxX - kStep) return {0, 0, 0};
  const double fx = x / kStep;
  const int ix = std::min(int(fx), kNx - 2);
  const double tx = fx - ix, ty = ty_;
  const double v00 = below_[ix], v01 = above_[ix], v10 = below_[ix + 1], v11 = above_[ix + 1];
  // Bilinear, and its own slopes: the fit's Jacobian is then that of the values it fits.
  return {(1 - tx) * ((1 - ty) * v00 + ty * v01) + tx * ((1 - ty) * v10 + ty * v11),
          ((1 - ty) * (v10 - v00) + ty * (v11 - v01)) / kStep,
          ((1 - tx) * (v01 - v00) + tx * (v11 - v10)) / kStep};
}

}  // namespace granmem
