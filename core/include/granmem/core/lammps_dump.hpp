#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"

namespace granmem {

// A LAMMPS text dump (`dump custom` or `dump atom`) read as granmem's long table: one row
// per atom per snapshot, columns frame (the snapshot's TIMESTEP), particle (the atom id
// less one: LAMMPS counts atoms from 1, granmem's grains from 0, as `export` maps them),
// x, y, z and, where the dump has them, radius, ax, ay, az, qw, qx, qy, qz and
// hole_contact. The dump's own names are mapped: x/xu (or scaled xs/xsu, turned into
// lengths with the snapshot's box), radius or diameter (halved), quatw/quati/quatj/quatk;
// other columns (type, velocities, computes) are read past.
struct LammpsDump {
  Table table;
  std::vector<std::size_t> lines;  // file line of each row, for messages
  std::size_t snapshots = 0;
  std::optional<Box> box;    // the first snapshot's box bounds
  bool box_changes = false;  // a later snapshot has other bounds (a moving boundary)
  std::string units;  // `ITEM: UNITS` where the dump has it (dump_modify units yes): si, cgs...
};

// Reads `path`. `types`: keep only atoms of these types (e.g. the grains, not a lid or wall
// particles); empty keeps all (a dump without a type column then). Throws Error naming the
// file and line for a dump that is not one (an ITEM out of place, a count that does not
// match its lines, a field that is not a number, a triclinic box).
LammpsDump read_lammps_dump(const std::filesystem::path& path, const std::set<long long>& types);

// The length unit of a LAMMPS `units` style ("si" -> m, "cgs" -> cm), or "" for styles
// whose length is not one of granmem's (lj, real, metal...).
std::string lammps_length_unit(const std::string& units_style);

}  // namespace granmem
