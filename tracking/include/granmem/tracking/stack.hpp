#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace granmem {

// One laser-sheet scan: a stack of 2D slices. Image coordinates: x runs along image
// columns, y along rows, z along slices (the scan direction); the centre of voxel (0,0,0)
// is the origin. Voxels are held as 16-bit values whatever the source's depth (8-bit
// sources keep their values, 0-255), x fastest, then y, then z: at most twice the size of
// an 8-bit source in memory.
struct Stack {
  std::int64_t nx = 0, ny = 0, nz = 0;
  int bits = 8;  // depth of the source: 8 or 16
  std::vector<std::uint16_t> voxels;
  // Voxel size (x, y, z) in `unit` (m, cm, mm, um), when the source or the user said.
  std::optional<Eigen::Vector3d> voxel_size;
  std::string unit;
  std::string source;  // file or folder, for messages

  Stack() = default;
  Stack(std::int64_t nx_, std::int64_t ny_, std::int64_t nz_, int bits_ = 8)
      : nx(nx_),
        ny(ny_),
        nz(nz_),
        bits(bits_),
        voxels(static_cast<std::size_t>(nx_ * ny_ * nz_), 0) {}

  std::size_t index(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return static_cast<std::size_t>((z * ny + y) * nx + x);
  }
  std::uint16_t& at(std::int64_t x, std::int64_t y, std::int64_t z) {
    return voxels[index(x, y, z)];
  }
  std::uint16_t at(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return voxels[index(x, y, z)];
  }
  // One slice (z) as a contiguous row-major ny x nx block.
  std::uint16_t* slice(std::int64_t z) { return voxels.data() + index(0, 0, z); }
  const std::uint16_t* slice(std::int64_t z) const { return voxels.data() + index(0, 0, z); }
  std::uint16_t max_value() const { return bits == 8 ? 255 : 65535; }
};

// A box of voxels [x0, x0+nx) x [y0, y0+ny) x [z0, z0+nz) to read instead of the whole stack.
struct Region {
  std::int64_t x0 = 0, y0 = 0, z0 = 0;
  std::int64_t nx = 0, ny = 0, nz = 0;  // 0: to the end along that axis
};

// A region as users type it: "x0,y0,z0,nx,ny,nz" in voxels, whole numbers >= 0. Throws Error
// naming `what` (the option) for anything else.
Region parse_region(const std::string& text, const std::string& what);

struct StackReadOptions {
  std::string dataset;           // HDF5 sources: the dataset, (z, y, x) order
  std::optional<Region> region;  // crop
  // The voxel size (x, y, z) in `unit` (m, cm, mm, um) as the user gave it (--voxel-size):
  // it replaces what the file says. With neither, the stack has no voxel size and results
  // stay in voxels.
  std::optional<Eigen::Vector3d> voxel_size;
  std::string unit;
};

// Reads a multi-page TIFF (8 or 16 bit, classic or BigTIFF), a folder of slice images
// (TIFF or PNG, in natural sort order: slice2 before slice10), or an HDF5 dataset. The voxel
// size comes from `options.voxel_size`, else from ImageJ or OME metadata (HDF5:
// element_size_um) when present. Throws Error with one line naming
// the file and what was expected (truncated or corrupt file, slices of unequal size, an
// empty folder, a dataset of the wrong rank, a region outside the stack).
Stack read_stack(const std::filesystem::path& source, const StackReadOptions& options = {});

// Writes a multi-page TIFF (8 or 16 bit as `stack.bits`, BigTIFF when over 4 GB) with
// ImageJ metadata carrying the voxel size, atomically (temporary file, then rename).
void write_tiff(const Stack& stack, const std::filesystem::path& path);

// Natural order of names: runs of digits compare as numbers ("scan2" < "scan10"), the
// order of slice files in a folder and of scans given to `granmem track`.
bool natural_less(const std::string& a, const std::string& b);

}  // namespace granmem
