#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "granmem/core/trajectories.hpp"

// Parsers for option values given as text (the command line, TOML, Python keywords).
namespace granmem {

// "xmin,ymin,zmin,xmax,ymax,zmax" -> Box.
Box parse_box(const std::string& text, const std::string& option, const std::string& run_unit = "");
// "A:B" -> (A, B), integers.
std::pair<std::int64_t, std::int64_t> parse_int_range(const std::string& text,
                                                      const std::string& option);
// "LO:HI" -> (LO, HI), numbers.
std::pair<double, double> parse_range(const std::string& text, const std::string& option);
// A length with an optional unit, in `run_unit`: "0.5" (run unit), "0.5 cm".
double parse_length(const std::string& text, const std::string& run_unit,
                    const std::string& option);

// "LX,LY,LZ<unit>" -> three positive edges (a container's) in `unit`; Error without a
// length unit.
Eigen::Vector3d parse_edges(const std::string& text, const std::string& unit,
                            const std::string& option);

// "X[,Y,Z][ unit]" -> a voxel size (one size: cubic voxels), positive, with the unit as
// given (empty when none).
struct VoxelSize {
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  std::string unit;
};
VoxelSize parse_voxel_size(const std::string& text, const std::string& option);

// "A=x,B=y" -> {A: x, B: y}: another program's names for granmem's columns. Error for an
// item without '=' or a name given twice.
std::map<std::string, std::string> parse_renames(const std::string& text,
                                                 const std::string& option);

// A time left, as a person reads it: "4m05s", "2h10m".
std::string duration_text(double seconds);

}  // namespace granmem
