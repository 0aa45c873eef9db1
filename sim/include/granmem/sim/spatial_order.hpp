#pragma once

#include "granmem/sim/simulation.hpp"

namespace granmem {

// The same packing, its grains relabelled 0..N-1 and stored in the order of horizontal
// layers, rows and positions along x, layers and rows one mean grain diameter apart: a
// grain's neighbours get near ids. The force pass walks the grains in id order, so their
// partners' data stay in cache (docs/BENCHMARKS.md). Positions, velocities, orientations,
// forces, every contact's and wall contact's springs, the container, time and step count
// are carried over: the continuation is the same physics, though not the same bits (each
// grain's forces are summed in the order of the new ids). Threads as the simulation had;
// the wall's motion is not carried (set it again). Throws Error for a grain whose position
// is not finite.
Simulation in_spatial_order(const Simulation& sim);

}  // namespace granmem
