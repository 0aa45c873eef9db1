// read_stack on arbitrary bytes as a .tif (classic and BigTIFF pages, ImageJ and OME
// metadata): a granmem::Error or a stack, never anything else.
#include "fuzz_input.hpp"
#include "granmem/core/error.hpp"
#include "granmem/tracking/stack.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    granmem::read_stack(granmem::fuzz::input_file(data, size, ".tif"));
  } catch (const granmem::Error&) {
  }
  return 0;
}
