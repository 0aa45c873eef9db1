#pragma once

#include <filesystem>
#include <string>

namespace granmem {

// `granmem info` as one call: what a trajectory store holds (producer, frames, grains and
// their radius, units, box, per-grain data, observables, parameters, every dataset with its
// shape and unit), as the text the command line prints. Throws Error for a file that is
// not a trajectory store.
std::string run_info(const std::filesystem::path& store);

}  // namespace granmem
