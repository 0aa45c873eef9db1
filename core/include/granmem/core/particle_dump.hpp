#pragma once

#include <filesystem>

#include "granmem/core/trajectory_store.hpp"

namespace granmem {

// Text formats OVITO (and ASE, VMD) read; OVITO cannot read H5MD.
enum class DumpFormat {
  lammps,  // LAMMPS text dump: id x y z radius [ax ay az] [quatw quati quatj quatk] [hole_contact]
  extxyz,  // extended XYZ with the same per-grain properties
};

// Writes every frame of a run, grains not seen in a frame left out of it (both formats
// carry the grain id, so OVITO still tracks them). Written atomically.
void write_particle_dump(const TrajectoryReader& run, const std::filesystem::path& out,
                         DumpFormat format);

}  // namespace granmem
