#pragma once

#include <Eigen/Core>

namespace granmem {

// The rotation a single tracked axis sees: the angle between two lines (the cavity axis
// is a line, so a and -a are the same axis), in radians in [0, pi/2]. Computed as
// atan2(|a1 x a2|, |a1 . a2|), which equals arccos(|a1 . a2|) for unit vectors but keeps
// full precision for small angles, where arccos loses half the digits. Axes need not be
// unit length; NaN if either is unknown (NaN) or of zero length.
double single_axis_angle(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2);

}  // namespace granmem
