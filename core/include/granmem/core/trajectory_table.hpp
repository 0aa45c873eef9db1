#pragma once

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"

namespace granmem {

// A run as one long table, the shape trackpy and pandas use: a row per grain seen in a
// frame (a known position), frames in order and grains in store order within each.
// Columns: frame (the frame's step: scan or cycle index), particle (the grain's id), time,
// x, y, z, radius (lengths in the run's unit), and where the run has them ax, ay, az (the
// cavity axis), qw, qx, qy, qz (the orientation), hole_contact, and a scan's standard
// errors ep_x, ep_y, ep_z (position, trackpy's `ep`) and axis_error (rad).
Table trajectory_table(const RunHeader& header);  // the columns, no rows
void append_frame(Table& table, const RunHeader& header, const Frame& frame);
Table trajectory_table(const Trajectories& run);

}  // namespace granmem
