#pragma once

#include <string>
#include <utility>

namespace granmem {

// How the driven wall moves in one cycle. Asymmetric: 0 -> A -> 0 (the paper's drive);
// symmetric: 0 -> A/2 -> -A/2 -> 0 (its appendix). Positive compresses the packing.
enum class DriveSymmetry { asymmetric, symmetric };
enum class DriveShape { cosine, linear };  // smooth start and stop, or constant speed

struct WallDrive {
  double amplitude = 0;  // A, m
  double period = 0;     // s
  DriveSymmetry symmetry = DriveSymmetry::asymmetric;
  DriveShape shape = DriveShape::cosine;

  // Wall position and velocity at time s into a cycle (0 <= s <= period).
  std::pair<double, double> at(double s) const;
  // Fastest wall speed over a cycle.
  double peak_speed() const;
  // Time into a cycle of the strongest compression (A, or A/2 for the symmetric drive).
  double full_compression_time() const;
  // The period whose peak speed is `speed`.
  static double period_for_speed(double amplitude, double speed, DriveSymmetry symmetry,
                                 DriveShape shape);
};

// An amplitude as given on the command line or in a checkpoint's settings: a percentage
// of the box's depth `box_y` along the drive ("1%") or a length with its unit ("0.15cm").
// Returns metres; Error naming `what` for anything else.
double parse_amplitude(const std::string& text, double box_y, const std::string& what);

DriveSymmetry parse_drive_symmetry(const std::string& text);
DriveShape parse_drive_shape(const std::string& text);

}  // namespace granmem
