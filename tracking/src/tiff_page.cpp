#include "tiff_page.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "granmem/core/error.hpp"

namespace granmem::stack_io {
namespace {

std::string photometric_name(std::uint16_t photometric) {
  switch (photometric) {
    case PHOTOMETRIC_RGB:
      return "RGB";
    case PHOTOMETRIC_PALETTE:
      return "palette colour";
    case PHOTOMETRIC_SEPARATED:
      return "CMYK";
    case PHOTOMETRIC_YCBCR:
      return "YCbCr colour";
    default:
      return "photometric interpretation " + std::to_string(photometric);
  }
}

// The page's strips or tiles: blocks of `width` x `height` pixels, row after row of blocks
// (a strip is a block as wide as the page), each decoded whole into a buffer of `row_bytes`
// per row.
struct Blocks {
  bool tiled = false;
  std::int64_t width = 0, height = 0, row_bytes = 0, bytes = 0;
};

Blocks page_blocks(TiffFile& file, const TiffPage& page, const std::string& where) {
  TIFF* tif = file.get();
  Blocks b;
  b.tiled = TIFFIsTiled(tif) != 0;
  if (b.tiled) {
    std::uint32_t tile_width = 0, tile_height = 0;
    TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_width);
    TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_height);
    b.width = tile_width;
    b.height = tile_height;
    b.row_bytes = static_cast<std::int64_t>(TIFFTileRowSize64(tif));
  } else {
    std::uint32_t rows_per_strip = 0;
    TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows_per_strip);
    b.width = page.width;
    b.height = std::clamp<std::int64_t>(rows_per_strip, 1, page.height);
    b.row_bytes = static_cast<std::int64_t>(TIFFScanlineSize64(tif));
  }
  b.bytes = b.height * b.row_bytes;
  // A tile may overhang its page (TIFF pads tiles to multiples of 16), but one beyond the
  // padded page and larger than any real tile is corrupt, and would have us allocate for
  // it (found by fuzz_tiff: a 13-row page in tiles of 268 million rows).
  auto padded = [](std::int64_t n) { return (n + 15) / 16 * 16; };
  constexpr std::int64_t kLargestOverhangingTile = std::int64_t(16) << 20;  // bytes
  const bool overhangs = b.width > padded(page.width) || b.height > padded(page.height);
  if (b.tiled && overhangs && b.bytes > kLargestOverhangingTile) {
    file.fail(where + ": tiles of " + std::to_string(b.width) + " x " + std::to_string(b.height) +
              " pixels on a page of " + std::to_string(page.width) + " x " +
              std::to_string(page.height) +
              ": inconsistent tile layout, expected a valid TIFF "
              "(file corrupt?)");
  }
  if (b.width <= 0 || b.height <= 0 || b.row_bytes < b.width * page.bits / 8) {
    file.fail(where + ": inconsistent " + (b.tiled ? "tile" : "strip") +
              " layout, expected a valid TIFF (file corrupt?)");
  }
  return b;
}

}  // namespace

void read_page(TiffFile& file, const TiffPage& page, const Box& box, std::uint16_t* out,
               const std::string& where) {
  TIFF* tif = file.get();
  const Blocks b = page_blocks(file, page, where);
  std::vector<unsigned char> buffer(static_cast<std::size_t>(b.bytes));
  for (std::int64_t by = box.y0 / b.height * b.height; by < box.y0 + box.ny; by += b.height) {
    // A strip at the bottom of the page holds fewer rows; a tile is always whole.
    const std::int64_t rows = b.tiled ? b.height : std::min(b.height, page.height - by);
    for (std::int64_t bx = box.x0 / b.width * b.width; bx < box.x0 + box.nx; bx += b.width) {
      const auto x = static_cast<std::uint32_t>(bx), y = static_cast<std::uint32_t>(by);
      const std::uint32_t block =
          b.tiled ? TIFFComputeTile(tif, x, y, 0, 0) : TIFFComputeStrip(tif, y, 0);
      const auto size = static_cast<tmsize_t>(buffer.size());
      const tmsize_t got = b.tiled ? TIFFReadEncodedTile(tif, block, buffer.data(), size)
                                   : TIFFReadEncodedStrip(tif, block, buffer.data(), size);
      if (got < rows * b.row_bytes || file.failed()) {
        file.fail(where + ": cannot read " + (b.tiled ? "tile " : "strip ") +
                  std::to_string(block) +
                  ", expected uncorrupted image data (file truncated or corrupt?)");
      }
      const std::int64_t x_begin = std::max(box.x0, bx);
      const std::int64_t x_end = std::min(box.x0 + box.nx, bx + b.width);
      const std::int64_t y_begin = std::max(box.y0, by);
      const std::int64_t y_end = std::min(box.y0 + box.ny, by + rows);
      for (std::int64_t row = y_begin; row < y_end; ++row) {
        copy_row(buffer.data() + (row - by) * b.row_bytes, page, x_begin - bx, x_end - x_begin,
                 out + (row - box.y0) * box.nx + (x_begin - box.x0));
      }
    }
  }
}

void copy_row(const unsigned char* row, const TiffPage& page, std::int64_t x0, std::int64_t nx,
              std::uint16_t* out) {
  if (page.bits == 8) {
    const unsigned char* in = row + x0;
    const std::uint16_t white = page.min_is_white ? 255 : 0;
    for (std::int64_t i = 0; i < nx; ++i)
      out[i] = static_cast<std::uint16_t>(white ? white - in[i] : in[i]);
  } else {
    // libtiff has already swapped 16-bit samples into the machine's byte order.
    std::memcpy(out, row + 2 * x0, static_cast<std::size_t>(nx) * 2);
    if (page.min_is_white) {
      for (std::int64_t i = 0; i < nx; ++i)
        out[i] = static_cast<std::uint16_t>(65535 - out[i]);
    }
  }
}

TiffPage describe_page(const TiffFile& file, const std::string& where) {
  TIFF* tif = file.get();
  TiffPage page;
  if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &page.width) ||
      !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &page.height) || page.width == 0 ||
      page.height == 0) {
    file.fail(where + ": no image size, expected a TIFF image");
  }
  std::uint16_t samples = 1, bits = 1, format = SAMPLEFORMAT_UINT, compression = 1;
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
  std::uint16_t photometric = PHOTOMETRIC_MINISBLACK;
  TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric);  // absent: assume grayscale
  if (samples != 1) {
    file.fail(where + ": " + std::to_string(samples) +
              " samples per pixel (colour?), expected a grayscale image");
  }
  if (photometric != PHOTOMETRIC_MINISBLACK && photometric != PHOTOMETRIC_MINISWHITE) {
    file.fail(where + ": " + photometric_name(photometric) + ", expected a grayscale image");
  }
  if (format == SAMPLEFORMAT_IEEEFP) {
    file.fail(where + ": floating-point samples, expected 8- or 16-bit unsigned integers");
  }
  if (format == SAMPLEFORMAT_INT) {
    file.fail(where + ": signed samples, expected 8- or 16-bit unsigned integers");
  }
  if (bits != 8 && bits != 16) {
    file.fail(where + ": " + std::to_string(bits) +
              "-bit samples, expected 8- or 16-bit grayscale");
  }
  if (!TIFFIsCODECConfigured(compression)) {
    file.fail(where + ": compression scheme " + std::to_string(compression) +
              " is not supported by this libtiff");
  }
  page.bits = bits;
  page.min_is_white = photometric == PHOTOMETRIC_MINISWHITE;
  return page;
}

}  // namespace granmem::stack_io
