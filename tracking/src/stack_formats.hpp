#pragma once

// Internal to the tracking library (and its tests): the readers and the writer behind
// read_stack() and write_tiff(), one per source format.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "granmem/tracking/stack.hpp"

namespace granmem::stack_io {

// A Region checked against a stack's size: every extent filled in and inside the stack.
struct Box {
  std::int64_t x0 = 0, y0 = 0, z0 = 0;
  std::int64_t nx = 0, ny = 0, nz = 0;
};

// The box to read from a stack of nx x ny x nz voxels: the whole stack without a region.
// Throws Error naming `source` when the region does not lie inside the stack.
Box resolve_region(const std::optional<Region>& region, std::int64_t nx, std::int64_t ny,
                   std::int64_t nz, const std::string& source);

// A stack of the box's size, its voxels zeroed; Error naming `source` if it cannot be held.
Stack allocate_stack(const Box& box, int bits, const std::string& source);

Stack read_tiff_stack(const std::filesystem::path& path, const std::optional<Region>& region);
Stack read_slice_folder(const std::filesystem::path& folder, const std::optional<Region>& region);
// Slice images (TIFF or PNG) in the order given, one per z; `source` names them in messages.
Stack read_slices(const std::vector<std::filesystem::path>& slices,
                  const std::optional<Region>& region, const std::string& source);
Stack read_hdf5_stack(const std::filesystem::path& path, const StackReadOptions& options);

// Classic TIFF holds at most 4 GB; BigTIFF has 64-bit offsets. `automatic` picks BigTIFF
// only when the data need it; tests force BigTIFF to check it on a small stack.
enum class TiffFormat { automatic, classic, big };
void write_tiff_stack(const Stack& stack, const std::filesystem::path& path, TiffFormat format);

}  // namespace granmem::stack_io
