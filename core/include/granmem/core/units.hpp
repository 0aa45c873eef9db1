#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace granmem {

// A number with an optional unit as a user types it: "0.5 cm", "25us", "12".
struct Quantity {
  double value = 0;
  std::string unit;  // empty when none was given
};

// `s` without leading and trailing white space.
std::string_view trim(std::string_view s);

// Parses "<number>[ ]<unit>". Throws Error naming `what` if the number is bad.
Quantity parse_quantity(std::string_view text, std::string_view what);

// Parses a comma list of quantities, "0.05,0.05,0.075 mm" or "1mm,1mm,2mm"; a unit on
// the last item applies to items without one. All items end up in one unit.
std::vector<Quantity> parse_quantity_list(std::string_view text, std::string_view what);

// Length units granmem reads and writes: m, cm, mm, um, and voxel (image coordinates).
bool is_physical_length_unit(std::string_view unit);
bool is_length_unit(std::string_view unit);

// Metres per one `unit` (a physical length unit); throws Error otherwise.
double metres_per(std::string_view unit);

// Converts between physical length units.
double convert_length(double value, std::string_view from, std::string_view to);

// What a configuration value measures; each accepts a few units, turned into SI.
enum class Dimension {
  length,
  time,
  mass,
  density,
  stiffness,
  acceleration,
  velocity,
  energy,
  pressure
};

// "4e6 g/s^2" -> 4000 (N/m). Without a unit, `default_unit` is assumed; with neither,
// or with a unit of another dimension, throws Error naming `what` and the units accepted.
double parse_si(std::string_view text, Dimension dimension, std::string_view default_unit,
                std::string_view what);

}  // namespace granmem
