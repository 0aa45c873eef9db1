#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "granmem/core/trajectories.hpp"

namespace granmem {

// The packing's structure from its grains' positions and radii alone, so that a scan and
// a simulation are measured alike (a simulation's lid height and box are not in a scan).
struct StructureOptions {
  // The region measured: by default the box of the grain centres' extent, shrunk by
  // `margin` median diameters on every side (away from the walls, floor and lid, where
  // the packing is layered).
  double margin = 2;
  std::optional<Box> region;
  // Two grains touch when their centres are closer than the sum of their radii times
  // 1 + contact_gap (located positions carry an error; simulated grains overlap a little).
  double contact_gap = 0.02;
};

struct PackingStructure {
  // Solid volume inside the region (each sphere's part in it) over the region's volume.
  double packing_fraction = std::numeric_limits<double>::quiet_NaN();
  // Mean number of touching neighbours of the grains whose centres are in the region.
  double coordination = std::numeric_limits<double>::quiet_NaN();
  std::size_t grains = 0;  // centres in the region
  Box region;
};

// Grains without a finite position are left out; a radius that is not known (NaN) is taken
// as the median of the known ones. NaN results when the region is empty or no radius is
// known.
PackingStructure packing_structure(const Vectors3& position, const std::vector<double>& radius,
                                   const StructureOptions& options = {});

// The packing fraction of the whole packing from its height: the grains' volume over the
// container's cross-section (`cross_section`, m^2 or the positions' unit squared) times
// the height from the packing's bottom to its top, which is where the floor and a free lid
// are: each the mean over a quarter of a layer's grains (the cross-section over 4 d^2) of
// the lowest grains' bottoms and the highest grains' tops, not the one extreme grain,
// whose place a scan's locating noise pushes outward. From positions alone, so a scan
// measures it as the DEM's lid does, without registering the scan to the container's
// floor. With `grains`, the count the packing is known to hold, the located grains' volume
// is scaled to it (a scan that missed some grains still sees the packing's height). NaN
// without grains or cross-section.
double height_packing_fraction(const Vectors3& position, const std::vector<double>& radius,
                               double cross_section, std::optional<std::size_t> grains = {});

}  // namespace granmem
