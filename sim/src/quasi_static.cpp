#include "granmem/sim/quasi_static.hpp"

#include <cmath>

namespace granmem {

double lid_mass_for_pressure(double pressure, double gravity, double box_x, double box_y) {
  return pressure * box_x * box_y / gravity;
}

double lid_pressure(double lid_mass, double gravity, double box_x, double box_y) {
  return lid_mass * gravity / (box_x * box_y);
}

double confining_stress(double lid_pressure, double density, double gravity, double diameter) {
  const double top = lid_pressure > 0 ? lid_pressure : density * 0.6 * gravity * diameter;
  return 0.5 * top;
}

double quasi_static_wall_speed(double inertial_number, double box_length, double diameter,
                               double pressure, double density) {
  return inertial_number * box_length * std::sqrt(pressure / density) / diameter;
}

double quasi_static_period(double inertial_number, const WallDrive& drive, double box_y,
                           double diameter, double stress, double density) {
  const double speed = quasi_static_wall_speed(inertial_number, box_y, diameter, stress, density);
  return WallDrive::period_for_speed(drive.amplitude, speed, drive.symmetry, drive.shape);
}

}  // namespace granmem
