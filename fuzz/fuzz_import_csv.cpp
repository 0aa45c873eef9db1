// import_table on arbitrary bytes as a CSV (or tab-separated) track table or a LAMMPS dump
// (a file starting with "ITEM:"; a seed in the corpus): a granmem::Error
// or a run, never anything else.
#include <string_view>

#include "fuzz_input.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  granmem::ImportOptions o;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (text.rfind("ITEM:", 0) == 0) {
    o.length_unit = "mm";  // a dump in lengths, its grains of type 1
    o.types = {1};
  } else {
    o.voxel_size = Eigen::Vector3d(0.4, 0.4, 0.6);  // the table in voxels, as trackers give it
    o.voxel_size_unit = "mm";
  }
  try {
    granmem::import_table(granmem::fuzz::input_file(data, size, ".csv"), o);
  } catch (const granmem::Error&) {
  }
  return 0;
}
