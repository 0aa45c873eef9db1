#pragma once

#include "granmem/sim/wall_drive.hpp"

namespace granmem {

// The protocol's time scale: how slowly the wall must move for the packing to pass through
// a sequence of static states. docs/QUASISTATIC.md has the measured limit.

// The paper's lid: 1 kg on 15 x 15 cm, 436 Pa. A smaller box keeps the paper's physics
// only under the same pressure (not the same mass).
inline constexpr double kPaperLidPressure = 1.0 * 9.81 / (0.15 * 0.15);  // Pa

// The default drive: the fastest inertial number whose steady state agrees with the
// slowest measured within two packings' difference (docs/QUASISTATIC.md), as a number and
// as the option's text.
inline constexpr double kQuasiStaticInertialNumber = 2e-3;
inline constexpr const char* kQuasiStaticInertialNumberText = "2e-3";

// Mass of a lid that presses with `pressure` on a box of floor `box_x` x `box_y`.
double lid_mass_for_pressure(double pressure, double gravity, double box_x, double box_y);
// Pressure of a lid of `lid_mass` on that floor.
double lid_pressure(double lid_mass, double gravity, double box_x, double box_y);

// The smallest confining stress in the packing, which sets how fast it relaxes: the
// lateral stress at its top, about half the vertical one there, which is the lid's
// pressure or, without a lid, the weight of one layer of grains (packing fraction 0.6).
double confining_stress(double lid_pressure, double density, double gravity, double diameter);

// The quasi-static limit: the inertial number I = (strain rate) d / sqrt(P / rho) of a
// packing of grain diameter d and density rho under pressure P, sheared at strain rate
// (wall speed / box length). Returns the wall speed that gives `inertial_number`.
double quasi_static_wall_speed(double inertial_number, double box_length, double diameter,
                               double pressure, double density);

// The period of a cycle of `drive` (its amplitude, symmetry and shape) whose peak wall
// speed gives `inertial_number` in a box of depth `box_y` along the drive under `stress`.
double quasi_static_period(double inertial_number, const WallDrive& drive, double box_y,
                           double diameter, double stress, double density);

}  // namespace granmem
