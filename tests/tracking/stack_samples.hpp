#pragma once

// Sample stacks for the stack reading and writing tests, and writers of foreign files
// (libtiff directly, HDF5's C API) to read them from.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <tiffio.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "checks.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem::testing {

// A value per voxel that differs between neighbours along every axis and, at 16 bits,
// uses both bytes (a swapped byte order would show).
inline std::uint16_t pattern_value(std::int64_t x, std::int64_t y, std::int64_t z, int bits) {
  const std::uint32_t v = static_cast<std::uint32_t>(x * 7 + y * 131 + z * 2029 + 3);
  return static_cast<std::uint16_t>(bits == 8 ? v % 256 : (v * 40503u) % 65536);
}

inline Stack pattern_stack(std::int64_t nx, std::int64_t ny, std::int64_t nz, int bits) {
  Stack s(nx, ny, nz, bits);
  for (std::int64_t z = 0; z < nz; ++z)
    for (std::int64_t y = 0; y < ny; ++y)
      for (std::int64_t x = 0; x < nx; ++x)
        s.at(x, y, z) = pattern_value(x, y, z, bits);
  return s;
}

// The box of `s` that a Region (all extents given) selects.
inline Stack crop(const Stack& s, const Region& r) {
  Stack c(r.nx, r.ny, r.nz, s.bits);
  for (std::int64_t z = 0; z < r.nz; ++z)
    for (std::int64_t y = 0; y < r.ny; ++y)
      for (std::int64_t x = 0; x < r.nx; ++x)
        c.at(x, y, z) = s.at(r.x0 + x, r.y0 + y, r.z0 + z);
  return c;
}

// Same size, depth and voxels, bit for bit.
inline void expect_same_voxels(const Stack& actual, const Stack& expected) {
  EXPECT_EQ(actual.nx, expected.nx);
  EXPECT_EQ(actual.ny, expected.ny);
  EXPECT_EQ(actual.nz, expected.nz);
  EXPECT_EQ(actual.bits, expected.bits);
  EXPECT_TRUE(actual.voxels == expected.voxels) << "voxels differ";
}

// A region that cuts into every axis of a stack of at least 12 x 12 x 3 voxels, and the
// same region as the readers must read it.
inline Region inner_region(const Stack& s) {
  return Region{3, 5, 1, s.nx - 7, s.ny - 9, s.nz - 2};
}

// Reading `source` throws Error with one line that starts with `name` (the source, or the
// slice file inside a source folder) and holds each of `words`.
inline void expect_read_error(const std::filesystem::path& source,
                              const std::vector<std::string>& words,
                              const StackReadOptions& options = {},
                              const std::filesystem::path& name = {}) {
  const std::string message = error_message([&] { read_stack(source, options); });
  const std::string lead = (name.empty() ? source : name).string();
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(lead + ":", 0), 0u) << message;
  for (const std::string& w : words)
    EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' not in: " << message;
}

inline std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
inline void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// How a foreign TIFF is laid out, as libtiff writes it.
struct TiffLayout {
  int tile = 0;  // tile edge (a multiple of 16); 0: strips
  std::uint32_t rows_per_strip = 4;
  std::uint16_t compression = COMPRESSION_NONE;  // LZW and Deflate with a predictor
  bool big = false;                              // BigTIFF
  bool big_endian = false;                       // "MM" byte order
  bool min_is_white = false;                     // samples stored inverted
  std::string description;                       // ImageDescription of the first page
  float x_resolution = 0, y_resolution = 0;      // 0: none
  std::uint16_t resolution_unit = RESUNIT_NONE;
};

// Slice z of `s` as page of the open file.
inline void write_tiff_page(TIFF* tif, const Stack& s, std::int64_t z, const TiffLayout& l) {
  const std::uint16_t max = s.max_value();
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, std::uint32_t(s.nx));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, std::uint32_t(s.ny));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, std::uint16_t(s.bits));
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, std::uint16_t(1));
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, std::uint16_t(SAMPLEFORMAT_UINT));
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, std::uint16_t(PLANARCONFIG_CONTIG));
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC,
               std::uint16_t(l.min_is_white ? PHOTOMETRIC_MINISWHITE : PHOTOMETRIC_MINISBLACK));
  TIFFSetField(tif, TIFFTAG_COMPRESSION, l.compression);
  if (l.compression != COMPRESSION_NONE) {
    TIFFSetField(tif, TIFFTAG_PREDICTOR, std::uint16_t(PREDICTOR_HORIZONTAL));
  }
  if (z == 0 && !l.description.empty()) {
    TIFFSetField(tif, TIFFTAG_IMAGEDESCRIPTION, l.description.c_str());
  }
  if (l.x_resolution > 0) {
    TIFFSetField(tif, TIFFTAG_XRESOLUTION, l.x_resolution);
    TIFFSetField(tif, TIFFTAG_YRESOLUTION, l.y_resolution);
    TIFFSetField(tif, TIFFTAG_RESOLUTIONUNIT, l.resolution_unit);
  }
  const int bytes = s.bits / 8;
  const auto sample = [&](std::int64_t x, std::int64_t y, unsigned char* out) {
    const std::uint16_t v =
        x < s.nx && y < s.ny ? (l.min_is_white ? max - s.at(x, y, z) : s.at(x, y, z)) : 0;
    if (bytes == 1) {
      *out = static_cast<unsigned char>(v);
    } else {
      std::memcpy(out, &v, 2);  // the machine's order: libtiff swaps for "MM" files
    }
  };
  if (l.tile > 0) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, std::uint32_t(l.tile));
    TIFFSetField(tif, TIFFTAG_TILELENGTH, std::uint32_t(l.tile));
    std::vector<unsigned char> tile(std::size_t(l.tile) * l.tile * bytes);
    for (std::int64_t ty = 0; ty < s.ny; ty += l.tile) {
      for (std::int64_t tx = 0; tx < s.nx; tx += l.tile) {
        for (int y = 0; y < l.tile; ++y)
          for (int x = 0; x < l.tile; ++x)
            sample(tx + x, ty + y, &tile[(std::size_t(y) * l.tile + x) * bytes]);
        ASSERT_GE(TIFFWriteTile(tif, tile.data(), std::uint32_t(tx), std::uint32_t(ty), 0, 0), 0);
      }
    }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, l.rows_per_strip);
    std::vector<unsigned char> row(std::size_t(s.nx) * bytes);
    for (std::int64_t y = 0; y < s.ny; ++y) {
      for (std::int64_t x = 0; x < s.nx; ++x)
        sample(x, y, &row[std::size_t(x) * bytes]);
      ASSERT_EQ(TIFFWriteScanline(tif, row.data(), std::uint32_t(y), 0), 1);
    }
  }
  ASSERT_EQ(TIFFWriteDirectory(tif), 1);
}

inline TIFF* open_tiff_for_writing(const std::filesystem::path& path, const TiffLayout& l) {
  const std::string mode = std::string("w") + (l.big ? "8" : "") + (l.big_endian ? "b" : "l");
  return TIFFOpen(path.c_str(), mode.c_str());
}

// `s` as a multi-page TIFF written by libtiff, one page per slice.
inline void write_libtiff(const std::filesystem::path& path, const Stack& s,
                          const TiffLayout& layout = {}) {
  TIFF* tif = open_tiff_for_writing(path, layout);
  ASSERT_NE(tif, nullptr);
  for (std::int64_t z = 0; z < s.nz; ++z)
    write_tiff_page(tif, s, z, layout);
  TIFFClose(tif);
}

// The first slice of each stack as a page of one TIFF: pages that need not agree.
inline void write_libtiff_pages(const std::filesystem::path& path,
                                const std::vector<Stack>& pages) {
  TIFF* tif = open_tiff_for_writing(path, {});
  ASSERT_NE(tif, nullptr);
  for (const Stack& page : pages)
    write_tiff_page(tif, page, 0, {});
  TIFFClose(tif);
}

// A dataset of the given shape (z, y, x for a stack) and file type, holding `values`
// (converted from 16 bits), written with HDF5's C API in a new file or one there;
// intermediate groups are created; `creation`: the dataset's properties (chunks, filters).
inline void write_hdf5(const std::filesystem::path& path, const std::string& name,
                       const std::vector<hsize_t>& dims, hid_t file_type,
                       const std::vector<std::uint16_t>& values, bool create = true,
                       hid_t creation = H5P_DEFAULT) {
  const hid_t file = create ? H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)
                            : H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  const hid_t links = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(links, 1);
  const hid_t dataset =
      H5Dcreate2(file, name.c_str(), file_type, space, links, creation, H5P_DEFAULT);
  EXPECT_GE(dataset, 0);
  EXPECT_GE(H5Dwrite(dataset, H5T_NATIVE_UINT16, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  H5Dclose(dataset);
  H5Pclose(links);
  H5Sclose(space);
  H5Fclose(file);
}

inline void write_hdf5_stack(const std::filesystem::path& path, const std::string& name,
                             const Stack& s, bool create = true) {
  write_hdf5(path, name, {hsize_t(s.nz), hsize_t(s.ny), hsize_t(s.nx)},
             s.bits == 8 ? H5T_STD_U8LE : H5T_STD_U16BE, s.voxels, create);
}

}  // namespace granmem::testing
