#pragma once

#include "granmem/tracking/stack.hpp"

namespace granmem {

// Normalised scans: voxel value = kNormalZero + f kNormalScale with f the "fluid fraction":
// 1 in the fluid, 0 in the grains (and in their holes, 1 again).
inline constexpr double kNormalZero = 16384, kNormalScale = 32768;
inline double fluid_fraction(std::uint16_t v) {
  return (double(v) - kNormalZero) / kNormalScale;
}

struct IlluminationOptions {
  double diameter = 12;     // grain diameter along the beam, voxels
  bool dark_grains = true;  // fluid bright; false: bright grains on dark fluid
  int beam_axis = 0;        // the laser's path: 0 along x (rows), 1 along y (columns)
  double fluid_percentile = 0.85, grain_percentile = 0.15;
};

// Removes what the illumination does to a scan: the fall-off along the laser's path, the
// slice-to-slice flicker and the streaks along the beam scale the light of the fluid, line
// by line of each slice. Voxels are split into fluid and grain halfway between each slice's
// fluid level (its own percentile: the light changes from slice to slice) and its grain
// level (the ratio of the two pooled over two diameters of slices: a slice between layers
// is nearly all fluid). The levels are read where nothing else leaks in: the fluid's from
// "deep" fluid, voxels two or more voxels in the slice and a slice away from any grain
// voxel (pure fluid whatever grains the packing puts near it), the dark level from voxels
// well inside grains. The fall-off is the deep fluid's mean along the beam (pooled over
// two diameters of slices and a diameter along the beam); each line's scale is the median
// of its deep fluid over the fall-off (a line with too few takes its neighbours' or its
// slice's). Each voxel becomes, in place,
// f = (I - dark level) / (line scale x fall-off - dark level): 1 in pure fluid, 0 in the
// grains. Memory: a byte per voxel besides the stack.
void normalize_illumination(Stack& stack, const IlluminationOptions& options);

// The same with one fluid and one grain level for the whole scan (percentiles of a sample
// of its voxels): for scans evenly lit, or already corrected.
void normalize_levels(Stack& stack, const IlluminationOptions& options);

}  // namespace granmem
