#pragma once

#include <string>

namespace granmem {

// This machine's physical memory in bytes (0 where it cannot be read).
double physical_memory();

// "2.5 GiB"
std::string gibibytes(double bytes);

// Refuses, before anything is allocated, work whose data would take more than half of this
// machine's memory: throws Error "<what> would take X GiB, more than half of this
// machine's Y GiB". `what` names the input ("deposit: 1e11 grains").
void check_memory_budget(double bytes, const std::string& what);

}  // namespace granmem
