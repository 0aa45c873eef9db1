#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/trajectories.hpp"

namespace granmem {

// The XDMF sidecar path of a run: run.h5 -> run.xmf.
std::filesystem::path xdmf_path(const std::filesystem::path& h5_path);

// Writes the XDMF sidecar that lets ParaView and VisIt open a trajectory store: a temporal
// collection of point clouds whose coordinates and attributes are hyperslabs of the
// HDF5 datasets (nothing is copied). `group` is the particles group, e.g. /particles/grains.
// The sidecar is left under its temporary name: commit() it once the HDF5 file is in
// place, so that a sidecar that cannot be written fails the run before an existing HDF5
// file of that name is replaced.
AtomicFile write_xdmf(const std::filesystem::path& h5_path, const std::string& group,
                      const RunHeader& header, const std::vector<std::int64_t>& steps,
                      const std::vector<double>& times);

}  // namespace granmem
