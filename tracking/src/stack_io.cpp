// read_stack() and write_tiff(): the source's format from its first bytes, and the
// region checks shared by the readers.
#include <array>
#include <charconv>
#include <cstring>
#include <fstream>
#include <new>
#include <string_view>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/memory_budget.hpp"
#include "granmem/core/units.hpp"
#include "granmem/tracking/stack.hpp"
#include "stack_formats.hpp"
#include "tiff_metadata.hpp"

namespace granmem {
namespace stack_io {
namespace {

enum class FileKind { tiff, png, hdf5, empty, unknown };

FileKind file_kind(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 8> head{};
  in.read(head.data(), head.size());
  const std::streamsize got = in.gcount();
  if (got == 0) return FileKind::empty;
  const auto starts = [&](const char* magic, std::size_t n) {
    return std::size_t(got) >= n && std::memcmp(head.data(), magic, n) == 0;
  };
  if (starts("II*\0", 4) || starts("MM\0*", 4) || starts("II+\0", 4) || starts("MM\0+", 4)) {
    return FileKind::tiff;
  }
  if (starts("\x89PNG\r\n\x1a\n", 8)) return FileKind::png;
  // HDF5's signature sits at 0, or at 512, 1024, 2048... behind a user block.
  const char signature[] = "\x89HDF\r\n\x1a\n";
  for (std::streamoff at = 0; at <= (std::streamoff(1) << 30); at = at ? 2 * at : 512) {
    in.clear();
    in.seekg(at);
    if (!in.read(head.data(), head.size())) break;
    if (std::memcmp(head.data(), signature, 8) == 0) return FileKind::hdf5;
  }
  return FileKind::unknown;
}

// "x [4, 20)"; an extent of 0 reads to the end: "x [4, end)".
std::string axis_text(const char* axis, std::int64_t start, std::int64_t size) {
  return std::string(axis) + " [" + std::to_string(start) + ", " +
         (size == 0 ? std::string("end") : std::to_string(start + size)) + ")";
}

}  // namespace

Box resolve_region(const std::optional<Region>& region, std::int64_t nx, std::int64_t ny,
                   std::int64_t nz, const std::string& source) {
  const std::string size = std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz);
  if (nx <= 0 || ny <= 0 || nz <= 0) {
    throw Error(source + ": an empty stack (" + size + " voxels), expected at least one voxel");
  }
  if (!region) return {0, 0, 0, nx, ny, nz};
  const Region& r = *region;
  Box box{r.x0, r.y0, r.z0, r.nx, r.ny, r.nz};
  const char* axes[] = {"x", "y", "z"};
  const std::int64_t full[] = {nx, ny, nz};
  std::int64_t* start[] = {&box.x0, &box.y0, &box.z0};
  std::int64_t* extent[] = {&box.nx, &box.ny, &box.nz};
  for (int a = 0; a < 3; ++a) {
    const std::int64_t s = *start[a], n = *extent[a];
    // Compared without forming s + n, which could overflow.
    if (s < 0 || s >= full[a] || n < 0 || n > full[a] - s) {
      throw Error(source + ": region " + axis_text(axes[a], s, n) +
                  " lies outside the stack, expected within " + axis_text(axes[a], 0, full[a]) +
                  " (the stack is " + size + " voxels)");
    }
    if (n == 0) *extent[a] = full[a] - s;  // to the end
  }
  return box;
}

Stack allocate_stack(const Box& box, int bits, const std::string& source) {
  check_memory_budget(2.0 * double(box.nx) * double(box.ny) * double(box.nz),
                      source + ": a stack of " + std::to_string(box.nx) + "x" +
                          std::to_string(box.ny) + "x" + std::to_string(box.nz) +
                          " voxels (read a region of it)");
  try {
    return Stack(box.nx, box.ny, box.nz, bits);
  } catch (const std::bad_alloc&) {
    throw Error(source + ": a stack of " + std::to_string(box.nx) + "x" + std::to_string(box.ny) +
                "x" + std::to_string(box.nz) + " voxels (" +
                std::to_string(2 * box.nx * box.ny * box.nz / (1 << 20)) +
                " MiB) does not fit in memory; read a region of it");
  } catch (const std::length_error&) {
    throw Error(source + ": a stack of " + std::to_string(box.nx) + "x" + std::to_string(box.ny) +
                "x" + std::to_string(box.nz) + " voxels is too large to hold");
  }
}

}  // namespace stack_io

Region parse_region(const std::string& text, const std::string& what) {
  const std::string expected = what + " '" + text + "': expected x0,y0,z0,nx,ny,nz in voxels";
  std::vector<std::int64_t> v;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string_view item = std::string_view(text).substr(
        start, comma == std::string::npos ? std::string::npos : comma - start);
    std::int64_t n = -1;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), n);
    if (ec != std::errc() || end != item.data() + item.size() || n < 0) throw Error(expected);
    v.push_back(n);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 6) throw Error(expected);
  return Region{v[0], v[1], v[2], v[3], v[4], v[5]};
}

Stack read_stack(const std::filesystem::path& source, const StackReadOptions& options) {
  const std::string name = source.string();
  if (options.voxel_size) {  // checked before any reading
    const Eigen::Vector3d& v = *options.voxel_size;
    if (!v.allFinite() || (v.array() <= 0).any() || !is_physical_length_unit(options.unit)) {
      throw Error(name + ": voxel size " + stack_io::shortest_text(v.x()) + "," +
                  stack_io::shortest_text(v.y()) + "," + stack_io::shortest_text(v.z()) + " '" +
                  options.unit + "', expected three positive sizes in m, cm, mm or um");
    }
  }
  std::error_code ec;
  if (!std::filesystem::exists(source, ec)) throw Error(name + ": no such file or folder");
  Stack stack;
  if (std::filesystem::is_directory(source, ec)) {
    if (!options.dataset.empty()) {
      throw Error(name + ": a folder, but a dataset ('" + options.dataset +
                  "') was given, expected an HDF5 file");
    }
    stack = stack_io::read_slice_folder(source, options.region);
  } else {
    const auto kind = stack_io::file_kind(source);
    if (!options.dataset.empty() && kind != stack_io::FileKind::hdf5) {
      throw Error(name + ": not an HDF5 file, but a dataset ('" + options.dataset + "') was given");
    }
    switch (kind) {
      case stack_io::FileKind::tiff:
        stack = stack_io::read_tiff_stack(source, options.region);
        break;
      case stack_io::FileKind::png:  // a stack of one slice
        stack = stack_io::read_slices({source}, options.region, name);
        break;
      case stack_io::FileKind::hdf5:
        stack = stack_io::read_hdf5_stack(source, options);
        break;
      case stack_io::FileKind::empty:
        throw Error(name + ": empty file, expected a TIFF stack, a PNG slice or an HDF5 file");
      case stack_io::FileKind::unknown:
        throw Error(name +
                    ": not a TIFF, PNG or HDF5 file, expected a multi-page TIFF, a folder of "
                    "slice images or an HDF5 dataset");
    }
  }
  if (options.voxel_size) {
    stack.voxel_size = options.voxel_size;
    stack.unit = options.unit;
  }
  stack.source = name;
  return stack;
}

void write_tiff(const Stack& stack, const std::filesystem::path& path) {
  stack_io::write_tiff_stack(stack, path, stack_io::TiffFormat::automatic);
}

}  // namespace granmem
