#pragma once

// Internal: the voxel size that ImageJ and OME-TIFF files carry, read and written.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "granmem/tracking/stack.hpp"
#include "tiff_file.hpp"

namespace granmem::stack_io {

struct TiffMetadata {
  std::optional<Eigen::Vector3d> voxel_size;
  std::string unit;                // m, cm, mm or um when voxel_size is set
  std::int64_t imagej_images = 0;  // ImageJ's "images=": the pages of the stack (0: not said)
};

// The metadata of an open TIFF file, from its current (first) page: ImageJ's
// ImageDescription with XResolution/YResolution, or OME-XML; empty for other files.
// Throws Error for an ImageJ or OME hyperstack of several channels, or of several time
// frames of a z stack: granmem reads one scan.
TiffMetadata read_tiff_metadata(const TiffFile& file);

// A length unit as files spell it ("micron", "µm", "nm", "mm"), as a granmem unit and the
// factor from the file's unit to it ("nm" -> um, 1e-3); nullopt for "pixel", a missing or
// an unknown unit: such files carry no voxel size.
struct LengthUnit {
  std::string unit;
  double factor = 1;
};
std::optional<LengthUnit> parse_length_unit(std::string_view text);

// The ImageDescription of an ImageJ stack: its size, and its unit and z spacing when the
// stack has a voxel size.
std::string imagej_description(const Stack& stack);

// A number as short text that reads back to the same double ("0.075").
std::string shortest_text(double value);

}  // namespace granmem::stack_io
