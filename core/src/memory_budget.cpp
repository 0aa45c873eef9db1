#include "granmem/core/memory_budget.hpp"

#include <unistd.h>

#include <sstream>

#include "granmem/core/error.hpp"

namespace granmem {

double physical_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

std::string gibibytes(double bytes) {
  std::ostringstream s;
  s.precision(2);
  s << bytes / double(1 << 30) << " GiB";
  return s.str();
}

void check_memory_budget(double bytes, const std::string& what) {
  const double memory = physical_memory();
  if (memory > 0 && bytes > 0.5 * memory) {
    throw Error(what + " would take " + gibibytes(bytes) + ", more than half of this machine's " +
                gibibytes(memory));
  }
}

}  // namespace granmem
