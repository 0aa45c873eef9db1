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
// by line of each slice. So, slice by slice, voxels are split into fluid and grain halfway
// between the slice's low and high levels; the fall-off is the fluid's mean intensity
// along the beam over all lines (smoothed over a diameter); each line's scale is the mean
// of its own fluid voxels over that profile (hundreds of them: precise), and its grain
// level the mean of its grain voxels. Each voxel becomes, in place,
// f = (I - grain level) / (line scale x fall-off - grain level).
void normalize_illumination(Stack& stack, const IlluminationOptions& options);

// The same with one fluid and one grain level for the whole scan (percentiles of a sample
// of its voxels): for scans evenly lit, or already corrected.
void normalize_levels(Stack& stack, const IlluminationOptions& options);

}  // namespace granmem
