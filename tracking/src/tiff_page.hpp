#pragma once

// Internal: one page (directory) of a TIFF file, checked and decoded into 16-bit voxels.

#include <cstdint>
#include <string>

#include "stack_formats.hpp"
#include "tiff_file.hpp"

namespace granmem::stack_io {

struct TiffPage {
  std::uint32_t width = 0, height = 0;
  int bits = 8;
  bool min_is_white = false;  // stored inverted: 0 is white
};

// The layout of the file's current page. Throws Error "<file>: <where>: ..." unless it is
// 8- or 16-bit unsigned grayscale that this libtiff can decode.
TiffPage describe_page(const TiffFile& file, const std::string& where);

// Decodes columns [box.x0, box.x0 + box.nx) of rows [box.y0, box.y0 + box.ny) of the
// current page into `out`, a row-major box.ny x box.nx block, reading only the strips or
// tiles those rows touch. Min-is-white pages are inverted so that 0 is black.
void read_page(TiffFile& file, const TiffPage& page, const Box& box, std::uint16_t* out,
               const std::string& where);

// Copies columns [x0, x0 + nx) of one decoded row of the page (samples in the machine's
// byte order) into 16-bit voxels.
void copy_row(const unsigned char* row, const TiffPage& page, std::int64_t x0, std::int64_t nx,
              std::uint16_t* out);

}  // namespace granmem::stack_io
