#pragma once

#include <cstddef>
#include <cstdint>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/grains.hpp"

namespace granmem {

// A packing placed where a frame of a run has its grains (an experiment's first scan, a
// simulation's first frame), instead of poured: the twin of an experiment started from the
// experiment's own packing, so that the packing-to-packing scatter of a pour (its density,
// its structure) is the experiment's and not the twin's. Positions only: a scan has no
// contact forces or velocities, so the placed grains start at rest with no contact history
// and are settled (settled_packing, under DepositOptions::placed_settling_damping, so that a
// scan's locating errors do not tap them denser) at the twin's friction before the drive.
//
// Each grain at its position in the frame, in the container's frame (the run's box corner
// at the origin) and in metres; a grain the frame misses at its position in the first later
// frame that has it (tracked ids), and left out if none has, or if a grain already placed
// lies within 0.75 d of it there (a track the linker broke between scans: that grain); no
// more of them than deposit.grains less the grains the frame has (a frame holding them all
// takes none), the farthest from the frame's grains first.
// Radii: the deposit's radius when it has no polydispersity (a scan's located radii carry
// its blur's bias), else the run's radius where known. Orientations: the run's where it has
// them, else turned so that the body's z axis (the cavity) is the frame's axis, else the
// identity.
// Throws Error if the run has no such frame, or its lengths are in voxels.
Grains grains_of_frame(const TrajectoryReader& run, std::size_t frame,
                       const DepositOptions& deposit, const PhysicsOptions& physics);

// The grains each moved by a normal draw of `jitter` (m, per coordinate) from `seed`, then
// kept inside the box of side deposit.box_side (x, y) and above the floor: one replica of a
// frame whose positions are known to about `jitter`.
Grains jittered(Grains grains, double jitter, std::uint64_t seed, const DepositOptions& deposit);

// The same with a jitter of its own along x, y and z (m): a frame moved by a scan's locating
// error, larger along z.
Grains jittered(Grains grains, const Eigen::Vector3d& jitter, std::uint64_t seed,
                const DepositOptions& deposit);

}  // namespace granmem
