#include "granmem/core/apparatus_readings.hpp"

#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/table.hpp"

namespace granmem {

namespace {

// The file's column and the name a simulation's store gives the same reading.
const std::pair<const char*, const char*> kReadings[] = {
    {"wall_force_full_compression", "wall_force_full_compression"},
    {"wall_force_unloaded", "wall_force"}};

std::string at_line(const std::filesystem::path& csv, std::size_t line) {
  return csv.string() + " line " + std::to_string(line);
}

std::vector<std::int64_t> cycles_of(const CsvColumns& read, const std::filesystem::path& csv) {
  std::vector<std::int64_t> cycles;
  std::set<std::int64_t> seen;
  const std::vector<double>& c = read.table["cycle"].values;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!(c[k] >= 0) || c[k] != std::floor(c[k]) || c[k] > 9e15) {
      throw Error(at_line(csv, read.lines[k]) + ", column 'cycle': expected a whole number >= 0");
    }
    cycles.push_back(std::int64_t(c[k]));
    if (!seen.insert(cycles.back()).second) {
      throw Error(at_line(csv, read.lines[k]) + ": cycle " + std::to_string(cycles.back()) +
                  " read twice");
    }
  }
  return cycles;
}

}  // namespace

std::map<std::string, Observable> read_apparatus_readings(const std::filesystem::path& csv) {
  std::vector<std::string> columns;
  for (const auto& [column, name] : kReadings)
    columns.push_back(column);
  const CsvColumns read = read_csv(csv, {"cycle"}, columns);
  const std::vector<std::int64_t> cycles = cycles_of(read, csv);
  std::map<std::string, Observable> readings;
  for (const auto& [column, name] : kReadings) {
    if (!read.table.has(column)) continue;
    Observable o;
    o.unit = "N";
    const std::vector<double>& v = read.table[column].values;
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (std::isnan(v[k])) continue;  // not read that cycle
      if (!(v[k] >= 0) || !std::isfinite(v[k])) {
        throw Error(at_line(csv, read.lines[k]) + ", column '" + column +
                    "': expected a force >= 0 in N");
      }
      o.value.push_back(v[k]);
      o.step.push_back(cycles[k]);
      o.time.push_back(double(cycles[k]));
    }
    readings.emplace(name, std::move(o));
  }
  if (readings.empty()) {
    throw Error(csv.string() +
                ": no column wall_force_full_compression or wall_force_unloaded "
                "(the apparatus' readings, N, beside a column cycle)");
  }
  return readings;
}

std::string attach_apparatus_readings(Trajectories& run, const std::filesystem::path& csv) {
  std::map<std::string, Observable> readings = read_apparatus_readings(csv);
  std::string said = "the apparatus' readings of " + csv.string() + ": the wall's force";
  for (const auto& [column, name] : kReadings) {
    const auto it = readings.find(name);
    if (it == readings.end()) continue;
    Observable& o = it->second;
    if (run.header.time_unit != "cycle") {
      for (std::size_t k = 0; k < o.step.size(); ++k) {
        o.time[k] = std::nan("");
        for (const Frame& f : run.frames)
          if (f.step == o.step[k]) o.time[k] = f.time;
      }
    }
    said += std::string(said.back() == 'e' ? " " : ", ") +
            (name == std::string("wall_force") ? "unloaded" : "at full compression") + " at " +
            std::to_string(o.value.size()) + " cycles";
    run.observables[name] = std::move(o);
  }
  return said;
}

}  // namespace granmem
