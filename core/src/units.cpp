#include "granmem/core/units.hpp"

#include <cctype>
#include <charconv>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

struct UnitScale {
  std::string_view name;
  double metres;
};
constexpr UnitScale kLengthUnits[] = {{"m", 1.0}, {"cm", 1e-2}, {"mm", 1e-3}, {"um", 1e-6}};

}  // namespace

Quantity parse_quantity(std::string_view text, std::string_view what) {
  const std::string_view s = trim(text);
  double value = 0;
  const char* begin = s.data();
  if (!s.empty() && s.front() == '+') ++begin;
  const auto [end, ec] = std::from_chars(begin, s.data() + s.size(), value);
  if (ec != std::errc() || end == begin) {
    throw Error(std::string(what) + ": expected a number with an optional unit, got '" +
                std::string(text) + "'");
  }
  return {value, std::string(trim(std::string_view(end, s.data() + s.size() - end)))};
}

std::vector<Quantity> parse_quantity_list(std::string_view text, std::string_view what) {
  std::vector<Quantity> items;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    items.push_back(parse_quantity(text.substr(start, comma - start), what));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  const std::string common = items.back().unit;
  for (Quantity& q : items) {
    if (q.unit.empty()) q.unit = common;
    if (q.unit != common) {
      throw Error(std::string(what) + ": give all values in one unit, got '" + std::string(text) +
                  "'");
    }
  }
  return items;
}

bool is_physical_length_unit(std::string_view unit) {
  for (const UnitScale& u : kLengthUnits) {
    if (u.name == unit) return true;
  }
  return false;
}

bool is_length_unit(std::string_view unit) {
  return unit == "voxel" || is_physical_length_unit(unit);
}

double metres_per(std::string_view unit) {
  for (const UnitScale& u : kLengthUnits) {
    if (u.name == unit) return u.metres;
  }
  throw Error("unknown length unit '" + std::string(unit) + "' (expected m, cm, mm or um)");
}

double convert_length(double value, std::string_view from, std::string_view to) {
  if (from == to) return value;
  return value * (metres_per(from) / metres_per(to));
}

namespace {

struct SiUnit {
  Dimension dimension;
  std::string_view name;
  double si;
};
constexpr SiUnit kSiUnits[] = {
    {Dimension::length, "m", 1.0},
    {Dimension::length, "cm", 1e-2},
    {Dimension::length, "mm", 1e-3},
    {Dimension::length, "um", 1e-6},
    {Dimension::time, "s", 1.0},
    {Dimension::time, "ms", 1e-3},
    {Dimension::time, "us", 1e-6},
    {Dimension::mass, "kg", 1.0},
    {Dimension::mass, "g", 1e-3},
    {Dimension::density, "kg/m^3", 1.0},
    {Dimension::density, "g/cm^3", 1e3},
    {Dimension::stiffness, "N/m", 1.0},
    {Dimension::stiffness, "kg/s^2", 1.0},
    {Dimension::stiffness, "g/s^2", 1e-3},
    {Dimension::stiffness, "dyn/cm", 1e-3},
    {Dimension::acceleration, "m/s^2", 1.0},
    {Dimension::acceleration, "cm/s^2", 1e-2},
    {Dimension::velocity, "m/s", 1.0},
    {Dimension::velocity, "cm/s", 1e-2},
    {Dimension::velocity, "mm/s", 1e-3},
    {Dimension::energy, "J", 1.0},
    {Dimension::energy, "erg", 1e-7},
    {Dimension::pressure, "Pa", 1.0},
    {Dimension::pressure, "kPa", 1e3},
    {Dimension::pressure, "N/m^2", 1.0},
    {Dimension::pressure, "dyn/cm^2", 0.1},
};

}  // namespace

double parse_si(std::string_view text, Dimension dimension, std::string_view default_unit,
                std::string_view what) {
  Quantity q = parse_quantity(text, what);
  if (q.unit.empty() && q.value == 0) return 0;  // zero in every unit ("--lid-pressure 0")
  if (q.unit.empty()) q.unit = std::string(default_unit);
  std::string accepted;
  for (const SiUnit& u : kSiUnits) {
    if (u.dimension != dimension) continue;
    if (u.name == q.unit) return q.value * u.si;
    accepted += (accepted.empty() ? "" : ", ") + std::string(u.name);
  }
  throw Error(
      std::string(what) + " '" + std::string(text) + "': " +
      (q.unit.empty() ? std::string("needs a unit") : "unit '" + q.unit + "' is not one of") +
      " (" + accepted + ")");
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())))
    s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())))
    s.remove_suffix(1);
  return s;
}

}  // namespace granmem
