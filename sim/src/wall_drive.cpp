#include "granmem/sim/wall_drive.hpp"

#include <cmath>

#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"

namespace granmem {

std::pair<double, double> WallDrive::at(double s) const {
  const double a = amplitude, t = period, phase = s / t;
  if (shape == DriveShape::cosine) {
    const double k = 2 * M_PI / t;
    if (symmetry == DriveSymmetry::asymmetric) {
      return {0.5 * a * (1 - std::cos(k * s)), 0.5 * a * k * std::sin(k * s)};
    }
    return {0.5 * a * std::sin(k * s), 0.5 * a * k * std::cos(k * s)};
  }
  if (symmetry == DriveSymmetry::asymmetric) {  // triangle 0 -> A -> 0
    const double v = 2 * a / t;
    return phase < 0.5 ? std::make_pair(v * s, v) : std::make_pair(v * (t - s), -v);
  }
  // 0 -> A/2 -> -A/2 -> 0 at constant speed: a path of 2A per period.
  const double v = 2 * a / t;
  if (phase < 0.25) return {v * s, v};
  if (phase < 0.75) return {0.5 * a - v * (s - 0.25 * t), -v};
  return {-0.5 * a + v * (s - 0.75 * t), v};
}

double WallDrive::peak_speed() const {
  if (shape == DriveShape::cosine) return M_PI * amplitude / period;
  return 2 * amplitude / period;
}

double WallDrive::full_compression_time() const {
  return symmetry == DriveSymmetry::asymmetric ? 0.5 * period : 0.25 * period;
}

double WallDrive::period_for_speed(double amplitude, double speed, DriveSymmetry,
                                   DriveShape shape) {
  // Both symmetries travel 2A per period; a cosine's peak speed is pi/2 times its mean.
  return shape == DriveShape::cosine ? M_PI * amplitude / speed : 2 * amplitude / speed;
}

double parse_amplitude(const std::string& text, double box_y, const std::string& what) {
  const std::string_view t = trim(text);
  if (!t.empty() && t.back() == '%') {
    const Quantity q = parse_quantity(t.substr(0, t.size() - 1), what);
    if (!q.unit.empty()) throw Error(what + " '" + text + "': expected a percentage, e.g. 1%");
    return q.value / 100 * box_y;
  }
  return parse_si(t, Dimension::length, "", what);
}

DriveSymmetry parse_drive_symmetry(const std::string& text) {
  if (text == "asymmetric") return DriveSymmetry::asymmetric;
  if (text == "symmetric") return DriveSymmetry::symmetric;
  throw Error("drive '" + text + "': expected asymmetric (0 -> A -> 0) or symmetric");
}

DriveShape parse_drive_shape(const std::string& text) {
  if (text == "cosine") return DriveShape::cosine;
  if (text == "linear") return DriveShape::linear;
  throw Error("wall motion '" + text + "': expected cosine or linear");
}

}  // namespace granmem
