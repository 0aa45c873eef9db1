#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"
#include "granmem/tracking/stack.hpp"

// Synthetic laser-sheet scans: grains (spheres with a cylindrical hole through the centre)
// drawn into a stack with the artefacts of real scans, every one adjustable, and the truth
// the image pipeline is measured against.
//
// The image is made as the instrument makes it. Each voxel's grain fraction phi (the grain
// material around its centre, weighted with a tent that reaches the neighbouring centres:
// exact in volume and centroid to ~1e-5 voxel at any sub-voxel position, so centroids carry
// no pixel locking; see cell_corner_shares in partial_volume.hpp) gives the emitted light
// fluid + (grain - fluid) * phi. The tent itself blurs a little (variance voxel^2 / 6 per
// axis); the PSF below comes on top of it. The laser sheet of slice z collects the light
// through its thickness (Gaussian PSF along z); the sheet's light falls off along its path
// (exp(-attenuation * s)), flickers from slice to slice and carries bright streaks along the beam;
// the camera blurs it (Gaussian PSF in x and y), adds shot noise (Poisson, `gain` per
// photoelectron) and read noise, and quantises it to the nearest grey value (a voxel all grain or
// all fluid is exactly round(level * full scale)). The light is carried in double precision.
namespace granmem {

// One grain to draw, in the grains' length unit.
struct RenderedGrain {
  std::int64_t id = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  // The cavity axis (unit, unsigned). NaN: drawn without a hole.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

// Dark grains in a bright (fluorescing) fluid, their holes bright; or the opposite contrast
// of some setups: bright grains on a dark fluid, with no hole seen.
enum class Polarity { dark_grains, bright_grains };

// Where the laser sheet comes from: it enters at that side of the stack and runs across
// it, along +x (from column 0), -x, +y (from row 0) or -y.
enum class Beam { plus_x, minus_x, plus_y, minus_y };

// The container wall seen edge-on: a line through every slice, x = position (axis 0) or
// y = position (axis 1), drawn with its partial volume.
struct WallLine {
  int axis = 0;
  double position = 0;   // its middle, in voxel coordinates
  double thickness = 3;  // voxels
  double level = 0.95;   // its brightness, as a fraction of full scale
};

struct RenderOptions {
  // --- Geometry ---
  // Voxel size (x, y, z) in the grains' length unit. Unset: the pixel is the median grain
  // diameter / `diameter_px`, and the slice spacing `slice_spacing_ratio` pixels.
  std::optional<Eigen::Vector3d> voxel_size;
  double diameter_px = 20;
  double slice_spacing_ratio = 1;
  // The position of the centre of voxel (0,0,0) and the stack size (nx, ny, nz). Unset:
  // the grains' extent plus `margin` voxels on every side.
  std::optional<Eigen::Vector3d> origin;
  std::optional<std::array<std::int64_t, 3>> size;
  double margin = 4;
  // The grains' length unit, recorded with the voxel size in the stack (m, cm, mm, um).
  std::string length_unit = "m";

  // --- Grains ---
  double hole_fraction = 0.3;  // hole diameter / grain diameter (dark_grains only)
  Polarity polarity = Polarity::dark_grains;
  // Intensities as fractions of full scale. Unset: fluid 0.75, grains 0.15 (dark grains);
  // fluid 0.1, grains 0.7 (bright grains).
  std::optional<double> fluid_level;
  std::optional<double> grain_level;
  // How far (voxels) the drawn surfaces may sit from the true ones before blur: voxels cut
  // by a surface are subdivided until the surface's curvature across a sub-box shifts it
  // less than this (a uniform shift: it changes the apparent radius, never the centre).
  double edge_tolerance = 0.002;

  // --- Optics ---
  // Gaussian PSF sigma (x, y, z) in voxels; z is the sheet's thickness. 0: none.
  Eigen::Vector3d blur_sigma{0.7, 0.7, 1.0};
  Beam beam = Beam::plus_x;
  // Light falls as exp(-attenuation * s), s the voxels travelled from where the beam enters.
  double attenuation = 3e-4;
  // Each slice's light times (1 + flicker * N(0,1)) (clamped at 0).
  double flicker = 0.02;
  // Bright lines along the beam: a Poisson number per slice with this mean, each at a
  // uniform position across the beam, raising the light by up to `streak_strength`
  // (uniform in [0, streak_strength]) at its middle with a Gaussian profile of sigma
  // `streak_width` voxels.
  double streaks_per_slice = 2;
  double streak_strength = 0.15;
  double streak_width = 1.5;
  std::optional<WallLine> wall;

  // --- Camera ---
  // Read noise: Gaussian, sigma as a fraction of full scale. Shot noise: the signal s
  // (fraction of full scale) is gain * Poisson(s / gain); 0 turns it off.
  double read_noise = 0.01;
  double gain = 5e-4;
  int bits = 8;  // 8 or 16

  std::uint64_t seed = 1;
  // Slices rendered together (memory: about (slices + PSF reach) * nx * ny floats);
  // 0: as many as fit in about 512 MB. The image does not depend on it.
  std::int64_t slices_per_block = 0;
  std::int64_t frame = 0;  // the scan index written in the truth's frame column

  // These options with every artefact off: no blur, attenuation, flicker, streaks, wall or
  // noise; only the grains and the quantisation.
  RenderOptions without_artefacts() const;
  double fluid() const;
  double grain() const;
  // Throws Error naming the first option out of its range ("render: ..., got <value>").
  void validate() const;
};

// Where the stack lies: resolved from the options and, where they leave it open, the grains.
struct ScanGeometry {
  Eigen::Vector3d voxel_size = Eigen::Vector3d::Ones();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // centre of voxel (0,0,0)
  std::int64_t nx = 0, ny = 0, nz = 0;

  // A position in the grains' unit -> voxel coordinates.
  Eigen::Vector3d to_voxels(const Eigen::Vector3d& position) const {
    return (position - origin).cwiseQuotient(voxel_size);
  }
};

// The voxel size that draws the median grain `diameter_px` pixels across, the slices
// `slice_spacing_ratio` pixels apart.
Eigen::Vector3d voxel_size_for(double median_radius, const RenderOptions& options);

// Throws Error naming the bad option or grain.
ScanGeometry scan_geometry(const std::vector<RenderedGrain>& grains, const RenderOptions& options);

// The truth of a rendered scan, one row per grain: frame, particle (the grain's id), x, y,
// z (voxel coordinates), radius (voxels along x), ax, ay, az (the cavity axis as given,
// unit; NaN where none), edge (1 where the grain is cut by the stack's border).
Table render_truth(const std::vector<RenderedGrain>& grains, const ScanGeometry& geometry,
                   std::int64_t frame = 0);

// Draws the grains (see the top of this file) and, when `truth` is given, fills it with
// render_truth's table. Slices are drawn in blocks, in parallel (OpenMP); the image depends
// only on the grains and the options, seed included, never on the thread count.
Stack render_scan(const std::vector<RenderedGrain>& grains, const RenderOptions& options,
                  Table* truth = nullptr);

// The grains of a trajectory-store frame, in the run's length unit: those with a position
// (NaN positions, grains not seen, are left out), each with its radius (a grain seen
// without a radius is an Error) and cavity axis: the frame's axis, else the body z axis of
// its orientation, else a random one (uniform on the sphere, from `seed` and the grain's id).
std::vector<RenderedGrain> rendered_grains(const Frame& frame, const RunHeader& header,
                                           std::uint64_t seed = 1);

}  // namespace granmem
