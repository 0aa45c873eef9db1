#pragma once

#include <filesystem>
#include <optional>

#include "granmem/core/trajectory_store.hpp"

namespace granmem {

// Text formats OVITO (and ASE, VMD) read, OVITO cannot read H5MD, and the long table
// analysis scripts read.
enum class DumpFormat {
  // LAMMPS text dump, as `read_dump` and OVITO read it: id type x y z radius [ax ay az]
  // [quatw quati quatj quatk] [hole_contact], where id is the granmem id + 1 (LAMMPS
  // numbers atoms from 1) and type is 1.
  lammps,
  // extended XYZ with the same per-grain properties, named as OVITO maps them (id, pos,
  // radius, orientation as OVITO's Orientation: x, y, z, w), the box as Lattice with its
  // corner as Origin and cell_origin.
  extxyz,
  // trackpy's long table as CSV: frame, particle, time, x, y, z, radius, ... (the columns
  // of trajectory_table.hpp), for pandas, MATLAB and TrackMate users.
  csv,
};

// Writes every frame of a run, grains not seen in a frame left out of it (both formats
// carry the grain id, so OVITO still tracks them). Written atomically.
void write_particle_dump(const TrajectoryReader& run, const std::filesystem::path& out,
                         DumpFormat format);

// One frame of a run as a LAMMPS data file that `read_data` starts a run from (`units si`,
// `atom_style sphere`): the box (the run's container, else the grains' bounding box), and
// one atom per grain seen in the frame, id = grain id + 1, type 1, its diameter and
// density, at rest. Lengths are converted to metres. `frame`: by index, default the last;
// `density` in kg/m^3, default the simulation's (the run's simulate/density). Throws Error
// for a run in voxels, a grain without a radius, a density neither given nor recorded or
// not positive, a frame the run does not have. Written atomically.
void write_lammps_data(const TrajectoryReader& run, std::optional<std::size_t> frame,
                       std::optional<double> density, const std::filesystem::path& out);

}  // namespace granmem
