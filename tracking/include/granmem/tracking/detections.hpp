#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"

namespace granmem {

// The grains found in one scan, a table with stable columns: frame, particle (the
// detection's index), x, y, z, radius, quality, edge (1: cut by the stack's border), ep_x,
// ep_y, ep_z (the centre's standard errors, trackpy's `ep`; NaN where unknown), and, where
// the cavity axis was looked for, ax, ay, az (unit, unsigned; NaN when not seen),
// axis_quality, axis_error (the axis' standard error, rad), hole_contact (1: touches a
// neighbour through its hole). Lengths in `length_unit` (voxel, or the unit of the voxel
// size). Tables without the standard errors (other programs', older files) read as NaN;
// trackpy's one `ep` reads as the same error on each axis.
struct Detections {
  std::int64_t frame = 0;  // scan index
  std::string length_unit = "voxel";
  std::optional<Eigen::Vector3d> voxel_size;  // in length_unit, when known
  std::string source;                         // the stack

  Vectors3 position;  // N x 3
  std::vector<double> radius, quality;
  std::vector<std::uint8_t> edge;
  Vectors3 position_error;  // N x 3
  bool has_axis = false;
  Vectors3 axis;  // N x 3 when has_axis
  std::vector<double> axis_quality, axis_error;
  std::vector<std::uint8_t> hole_contact;

  std::size_t size() const { return static_cast<std::size_t>(position.rows()); }
  // Appends one detection (standard errors and axis fields NaN/0 until set).
  void add(const Eigen::Vector3d& x, double r, double q, bool on_edge);
};

Table to_table(const Detections& d);
Detections from_table(const Table& t, const std::string& where);

// Detections file: HDF5 (the table under /detections, with attributes length_unit,
// voxel_size, source, frame) or, for a .csv name, the CSV table. Written atomically.
void write_detections(const Detections& d, const std::filesystem::path& path);
Detections read_detections(const std::filesystem::path& path);

}  // namespace granmem
