#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace granmem {

// The angle of the rotation R that takes a grain from orientation q1 to q2 (R = q2 q1^-1),
// in radians in [0, pi]: the paper's arccos((trace R - 1) / 2), computed as
// 2 atan2(|v|, |w|) of the relative quaternion (w, v), exact for small angles too.
// NaN if either quaternion is unknown.
double full_rotation_angle(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q2);

// The same from three tracked body axes: the columns of P1 and P2 are the grain's
// principal axes before and after, R P1 = P2, so R = P2 P1^T.
double full_rotation_angle(const Eigen::Matrix3d& p1, const Eigen::Matrix3d& p2);

// The cavity axis of a simulated grain: its body z axis in the lab frame.
Eigen::Vector3d cavity_axis(const Eigen::Quaterniond& orientation);

}  // namespace granmem
