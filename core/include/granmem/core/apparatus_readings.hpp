#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "granmem/core/trajectories.hpp"

namespace granmem {

// The apparatus' own readings of an experiment, cycle by cycle, beside its scans: a load
// cell's force on the driven wall, which the DEM twin reports as well and which pins the
// friction where the positions alone cannot (docs/CALIBRATION.md, "The wall's force read
// beside the scans").
//
// A CSV (read_csv: comments, quoted fields, TSV) with the column `cycle` (the cycle at whose
// full compression or end the reading was taken, as the scans number theirs) and one or
// both of
//   wall_force_full_compression  N, the force the packing exerts on the driven wall at full
//                                compression
//   wall_force_unloaded          N, the same at the cycle's end, the wall back at its start
// empty or nan where not read. Returned under the names a simulation's store gives them
// (wall_force_full_compression, wall_force), unit N, step the cycle, time the cycle.
// Throws Error naming the file (and line): no cycle column or neither force, a cycle that
// is not a whole number >= 0, a cycle twice, a force that is negative or not finite.
std::map<std::string, Observable> read_apparatus_readings(const std::filesystem::path& csv);

// Adds the readings of `csv` to `run`'s observables (time: the cycle where the run counts
// in cycles, else the time of the run's frame of that cycle, NaN without one); returns a
// line saying what was added.
std::string attach_apparatus_readings(Trajectories& run, const std::filesystem::path& csv);

}  // namespace granmem
