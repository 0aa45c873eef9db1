#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"

namespace granmem {

// How to read a long-form table of tracked grains (trackpy, a lab's MATLAB code):
// one row per grain per frame, columns frame,particle,x,y,z and optionally ax,ay,az
// (cavity axis, any length, any sign), radius, hole_contact (0/1), a scan's standard
// errors ep_x, ep_y, ep_z (or trackpy's one `ep`; the positions' unit, scaled as they are)
// and axis_error (rad, kept as given: with voxels of unequal sides, the angle in the
// table's voxel space), in any order.
struct ImportOptions {
  // Unit of x, y, z and radius in the table: m, cm, mm, um, or voxel.
  std::string length_unit = "voxel";
  // With voxel coordinates: the voxel size (x, y, z) in `voxel_size_unit`. Positions, axes
  // and radii are then turned into lengths, axis by axis (radius with the x size).
  std::optional<Eigen::Vector3d> voxel_size;
  std::string voxel_size_unit;
  // Radius of every grain when the table has no radius column (table's unit).
  std::optional<double> radius;
  // Container as (xmin, ymin, zmin, xmax, ymax, zmax) in the table's unit.
  std::optional<Box> box;
  std::string sample = kSampleEndOfCycle;
  // Other programs' column names and header rows (TrackMate, MATLAB; files only).
  CsvReadOptions csv;
  // LAMMPS dumps: the atom types that are grains (not a lid or wall particles); empty
  // keeps every atom.
  std::set<long long> types;
  // The apparatus' readings beside the table (a load cell's force on the driven wall, cycle
  // by cycle: apparatus_readings.hpp), stored as the run's observables. Empty: none.
  std::filesystem::path readings;

  // Throws Error naming the option: an unknown length unit, a voxel size without voxel
  // coordinates, a length unit or three positive sizes, a radius that is not positive.
  void validate() const;
};

struct ImportSummary {
  std::size_t rows = 0;
  std::size_t frames = 0;
  std::size_t grains = 0;
  std::size_t missing = 0;         // (frame, grain) pairs with no row
  std::size_t axes_known = 0;      // rows with a cavity axis
  std::string length_unit;         // unit of the stored positions
  std::string format;              // "csv" or "lammps dump"
  std::vector<std::string> notes;  // what was taken from the file, for the user
  std::string source;              // the table's name
  bool has_axis = false;
  // What the command line prints: the counts, the notes, the unit.
  std::string Report() const;
};

// Reads the table into a run: frames in increasing `frame` order (step = frame label),
// grains in increasing `particle` order (id = particle label). A grain missing from a
// frame gets NaN. Throws Error naming file, line and column for bad rows. A file that
// starts with "ITEM:" is read as a LAMMPS text dump (core/lammps_dump.hpp): snapshots
// become frames (step = TIMESTEP), atoms grains (id = atom id); its length unit is the
// dump's `ITEM: UNITS` where it has one (it must then agree with a --length-unit other
// than voxel) and must be given where it has none; its box is the first snapshot's
// bounds unless `box` is given.
Trajectories import_table(const std::filesystem::path& csv, const ImportOptions& options,
                          ImportSummary* summary = nullptr);
// The same from a table in memory (a pandas DataFrame's columns); `source` names it in
// messages, its rows counted from 1.
Trajectories import_table(const Table& table, const std::string& source,
                          const ImportOptions& options, ImportSummary* summary = nullptr);

}  // namespace granmem
