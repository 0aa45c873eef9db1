#pragma once

#include <filesystem>
#include <string>

#include "granmem/sim/container.hpp"
#include "granmem/sim/grains.hpp"

// A packing as a LAMMPS data file (CGS): what `granmem simulate --engine lammps` and
// bench/compare_lammps.sh start LAMMPS from (sim/lammps/*.lmp read it).
namespace granmem {

struct LammpsDataOptions {
  double density = 1180;  // the grains' density, kg/m^3
  // atom_style hybrid sphere dipole, the dipole the grain's cavity axis (its body z axis),
  // which `fix nve/sphere update dipole` turns with the grain; else atom_style sphere.
  bool cavity_axis_as_dipole = false;
  std::string comment;  // the file's first line, after what wrote it
};

// Grain id + 1, type 1, diameter, density, position (and the dipole); the lid, when there
// is one, atom N + 1 of type 2, a point particle (diameter 0, so its density column is its
// mass in g) in the middle of the box at the height of its lower face. Velocities and
// angular velocities follow. The box: x, y in [0, side], z from -0.5 cm to well above the
// top. No contact histories: a data file has none. Through the atomic writer.
void write_lammps_data(const std::filesystem::path& path, const Grains& grains,
                       const Container& container, const LammpsDataOptions& options);

}  // namespace granmem
