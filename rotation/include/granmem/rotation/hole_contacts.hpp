#pragma once

#include <cstdint>
#include <vector>

#include "granmem/core/trajectories.hpp"

namespace granmem {

struct HoleContactOptions {
  // Hole diameter over grain diameter. Seen from the grain's centre, the hole's mouth spans
  // a half-angle asin(hole_fraction) around the axis (17.5 deg for 0.3).
  double hole_fraction = 0.3;
  // Touching: centre distance under (r_i + r_j) (1 + gap); a located radius runs a few
  // per cent small and a neighbour's centre a few hundredths of a voxel off.
  double gap = 0.05;
};

// For each grain, 1 when a neighbour touches it inside its hole's mouth: the neighbour's
// centre direction within the mouth's half-angle of the axis (either end) and the two
// touching. The paper leaves such grains out of the measured rotations, as the hole locks
// on the neighbour. A grain without an axis (NaN) is never flagged; it may still flag its
// neighbours. Centres, radii in one length unit; axes need not be unit length.
std::vector<std::uint8_t> hole_contacts(const Vectors3& centre, const std::vector<double>& radius,
                                        const Vectors3& axis,
                                        const HoleContactOptions& options = {});

}  // namespace granmem
