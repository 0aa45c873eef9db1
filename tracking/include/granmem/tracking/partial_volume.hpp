#pragma once

#include <Eigen/Core>
#include <array>

// Partial volumes of grains in voxels: how much of a voxel (a box) a grain occupies, and
// the same volume shared among voxel centres with trilinear weights, the sampling the
// synthetic-scan renderer draws with (see cell_corner_shares).
namespace granmem {

// Fraction of the unit cube [-1/2, 1/2]^3 where m . u <= d. Exact (a piecewise cubic of d),
// for any m including zeros; m = 0 gives 1 for d >= 0, else 0.
double unit_cube_fraction_below_plane(const Eigen::Vector3d& m, double d);

// A grain: a sphere with a cylindrical hole through its centre along `axis` (unit).
// hole_radius 0: no hole. Any length unit, the same for every argument below.
struct GrainShape {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double hole_radius = 0;
};

// Fraction of the box centred at `box_centre` with half-sides `half_size` that is grain
// material (inside the sphere, outside the hole). Boxes crossed by a surface are split in
// eight, `levels` times; in each final box the surface is taken as the plane tangent at
// the point nearest the box centre and the box volume under it is exact. What remains is
// the surface's curvature across a final box: a uniform shift of the surface by about
// s^2 / (12 r) for a box of side s and curvature radius r (the sphere's radius, twice the
// hole's), which moves no centre. Boxes crossed by both surfaces (the hole's rims) multiply
// the two fractions.
double occupied_fraction(const GrainShape& grain, const Eigen::Vector3d& box_centre,
                         const Eigen::Vector3d& half_size, int levels);

// The fewest splitting levels (at most `max_levels`) that keep that shift of a grain's
// surfaces under `tolerance` voxels, for voxels of `voxel_size` (tolerance in units of the
// smallest side). The shift across a final box of sides a (x, y, z) whose surface has the
// normal n is sum_i a_i^2 (1 - n_i^2) / (24 r) on the sphere, at most the two longest
// sides' squares over 24 r; on the hole's wall, curved one way, at most the longest
// side's square over 24 times the hole's radius.
// The grain material of one cell between eight voxel centres, the box [lo, lo + size],
// shared among its corners with trilinear weights: corner k (at lo + size * (k & 1,
// (k >> 1) & 1, (k >> 2) & 1)) gets the integral over the cell of grain material times
// (1 - |x - corner| / size) per axis, divided by the cell's volume. The shares add up to
// the cell's occupied fraction (same splitting as occupied_fraction); a cell wholly in the
// grain gives exactly 1/8 to each corner.
//
// Summed over the eight cells around a voxel centre, the shares are the grain sampled with
// a tent (the voxel's box convolved with a box of one voxel). A box-sampled image (each
// voxel its occupied fraction) keeps the volume but not the centre: its spectrum vanishes
// at the sampling frequencies, not its slope, and the image's centroid swings with the
// sub-voxel position (a few 1e-3 voxel for a 10-voxel grain). The tent's spectrum vanishes
// there to second order, so the image's volume and centroid are those of the grain (up to
// the splitting's residue, ~1e-5 voxel at the levels refinement_levels picks).
std::array<double, 8> cell_corner_shares(const GrainShape& grain, const Eigen::Vector3d& lo,
                                         const Eigen::Vector3d& size, int levels);

int refinement_levels(const GrainShape& grain, const Eigen::Vector3d& voxel_size, double tolerance,
                      int max_levels = 5);

}  // namespace granmem
