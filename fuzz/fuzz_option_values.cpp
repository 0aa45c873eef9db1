// The parsers of option values (the command line's, TOML's, Python's keywords): lengths
// with units, lists, ranges, renames. A value or a granmem::Error, never anything else.
#include <string>

#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto quietly = [](auto parse) {
    try {
      parse();
    } catch (const granmem::Error&) {
    }
  };
  quietly([&] { granmem::parse_quantity(text, "--x"); });
  quietly([&] { granmem::parse_quantity_list(text, "--x"); });
  quietly([&] { granmem::parse_si(text, granmem::Dimension::length, "m", "--x"); });
  quietly([&] { granmem::parse_int_range(text, "--x"); });
  quietly([&] { granmem::parse_range(text, "--x"); });
  quietly([&] { granmem::parse_box(text, "--x", "mm"); });
  quietly([&] { granmem::parse_length(text, "mm", "--x"); });
  quietly([&] { granmem::parse_edges(text, "mm", "--x"); });
  quietly([&] { granmem::parse_voxel_size(text, "--x"); });
  quietly([&] { granmem::parse_renames(text, "--x"); });
  return 0;
}
