#include "granmem/core/option_values.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

std::pair<std::string, std::string> split_colon(const std::string& text,
                                                const std::string& option) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) {
    throw Error(option + " '" + text + "': expected FIRST:LAST");
  }
  return {text.substr(0, colon), text.substr(colon + 1)};
}

double plain_number(const std::string& text, const std::string& option) {
  const Quantity q = parse_quantity(text, option);
  if (!q.unit.empty()) throw Error(option + " '" + text + "': expected a plain number");
  return q.value;
}

}  // namespace

Box parse_box(const std::string& text, const std::string& option, const std::string& run_unit) {
  const std::vector<Quantity> v = parse_quantity_list(text, option);
  const std::string unit = v.empty() ? "" : v.front().unit;
  const bool convert = !unit.empty() && unit != run_unit;
  if (v.size() != 6 || (convert && (run_unit.empty() || !is_physical_length_unit(unit) ||
                                    !is_physical_length_unit(run_unit)))) {
    throw Error(
        option + " '" + text + "': expected six numbers xmin,ymin,zmin,xmax,ymax,zmax in " +
        (run_unit.empty() ? std::string("the table's unit") : "a length unit or " + run_unit));
  }
  Box box;
  for (int k = 0; k < 3; ++k) {
    auto at = [&](std::size_t i) {
      return convert ? convert_length(v[i].value, unit, run_unit) : v[i].value;
    };
    box.lower[k] = at(std::size_t(k));
    box.edges[k] = at(std::size_t(k) + 3) - box.lower[k];
  }
  if (!(box.edges.array() > 0).all() || !box.lower.allFinite() || !box.edges.allFinite()) {
    throw Error(option + " '" + text + "': each max must be greater than its min");
  }
  return box;
}

std::pair<std::int64_t, std::int64_t> parse_int_range(const std::string& text,
                                                      const std::string& option) {
  const auto [a, b] = split_colon(text, option);
  const double lo = plain_number(a, option), hi = plain_number(b, option);
  // Frame labels are 64-bit integers; beyond 2^53 a double no longer holds every one.
  constexpr double kLargest = 9007199254740992.0;
  if (lo != std::floor(lo) || hi != std::floor(hi) || !(std::abs(lo) <= kLargest) ||
      !(std::abs(hi) <= kLargest)) {
    throw Error(option + " '" + text + "': expected whole frame numbers");
  }
  return {static_cast<std::int64_t>(lo), static_cast<std::int64_t>(hi)};
}

std::pair<double, double> parse_range(const std::string& text, const std::string& option) {
  const auto [a, b] = split_colon(text, option);
  return {plain_number(a, option), plain_number(b, option)};
}

double parse_length(const std::string& text, const std::string& run_unit,
                    const std::string& option) {
  const Quantity q = parse_quantity(text, option);
  if (!std::isfinite(q.value) || q.value < 0) {
    throw Error(option + " '" + text + "': expected a non-negative length");
  }
  if (q.unit.empty() || q.unit == run_unit) return q.value;
  if (!is_physical_length_unit(q.unit) || !is_physical_length_unit(run_unit)) {
    throw Error(option + " '" + text + "': cannot convert " + q.unit + " to the run's unit " +
                run_unit);
  }
  return convert_length(q.value, q.unit, run_unit);
}

// "LX,LY,LZ<unit>" -> the edges in `unit` (Error without a length unit or a positive edge).
Eigen::Vector3d parse_edges(const std::string& text, const std::string& unit,
                            const std::string& option) {
  const std::vector<Quantity> v = parse_quantity_list(text, option);
  if (v.size() != 3 || !is_physical_length_unit(v.back().unit)) {
    throw Error(option + " '" + text + "': expected LX,LY,LZ with a length unit, e.g. 5,5,7cm");
  }
  Eigen::Vector3d edges;
  for (int a = 0; a < 3; ++a) {
    edges[a] = convert_length(v[std::size_t(a)].value, v.back().unit, unit);
    if (!(edges[a] > 0) || !std::isfinite(edges[a])) {
      throw Error(option + " '" + text + "': each edge must be positive");
    }
  }
  return edges;
}

std::map<std::string, std::string> parse_renames(const std::string& text,
                                                 const std::string& option) {
  std::map<std::string, std::string> out;
  std::stringstream items(text);
  for (std::string item; std::getline(items, item, ',');) {
    const std::size_t eq = item.find('=');
    const std::string from(trim(item.substr(0, eq)));
    const std::string to(eq == std::string::npos ? "" : trim(item.substr(eq + 1)));
    if (from.empty() || to.empty()) {
      throw Error(option + " '" + text + "': expected NAME=column,... e.g. POSITION_X=x");
    }
    if (!out.emplace(from, to).second) {
      throw Error(option + " '" + text + "': " + from + " is named twice");
    }
  }
  return out;
}

VoxelSize parse_voxel_size(const std::string& text, const std::string& option) {
  const std::vector<Quantity> v = parse_quantity_list(text, option);
  if (v.size() != 1 && v.size() != 3) {
    throw Error(option + " '" + text + "': expected one size or three (x,y,z), with a unit");
  }
  VoxelSize out;
  out.unit = v.front().unit;
  for (int a = 0; a < 3; ++a) {
    const double value = v[v.size() == 1 ? 0 : std::size_t(a)].value;
    if (!std::isfinite(value) || !(value > 0)) {
      throw Error(option + " '" + text + "': sizes must be positive");
    }
    out.size[a] = value;
  }
  return out;
}

std::string duration_text(double seconds) {
  const auto s = std::llround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  else
    std::snprintf(buf, sizeof buf, "%lldm%02llds", s / 60, s % 60);
  return buf;
}

}  // namespace granmem
