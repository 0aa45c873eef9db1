// Multi-page TIFF stacks: one page per slice, read page by page with libtiff.
#include <algorithm>
#include <fstream>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/memory_budget.hpp"
#include "stack_formats.hpp"
#include "tiff_file.hpp"
#include "tiff_metadata.hpp"
#include "tiff_page.hpp"

namespace granmem::stack_io {
namespace {

std::string page_text(std::int64_t z, std::int64_t pages) {
  return "page " + std::to_string(z + 1) + " of " + std::to_string(pages);
}

// ImageJ saves a stack over 4 GB as a classic TIFF with one page directory and
// "images=N" in its description, the N images stored one after the other behind the
// first page's data. Reads the box from such a file.
void read_imagej_contiguous(TiffFile& file, const std::filesystem::path& path, const TiffPage& page,
                            std::int64_t images, const Box& box, Stack& stack) {
  TIFF* tif = file.get();
  std::uint16_t compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
  const std::string layout =
      "ImageJ stack of " + std::to_string(images) + " images with a single page directory";
  if (compression != COMPRESSION_NONE || TIFFIsTiled(tif)) {
    file.fail(layout + ": compressed or tiled, expected uncompressed strips");
  }
  const std::uint64_t* offsets = nullptr;
  const std::uint64_t* counts = nullptr;
  if (!TIFFGetField(tif, TIFFTAG_STRIPOFFSETS, &offsets) ||
      !TIFFGetField(tif, TIFFTAG_STRIPBYTECOUNTS, &counts) || !offsets || !counts) {
    file.fail(layout + ": no strip offsets");
  }
  const std::int64_t sample_bytes = page.bits / 8;
  const std::int64_t page_bytes = std::int64_t(page.width) * page.height * sample_bytes;
  const std::uint32_t strips = TIFFNumberOfStrips(tif);
  std::uint64_t end = offsets[0];
  for (std::uint32_t s = 0; s < strips; ++s) {
    if (offsets[s] != end) file.fail(layout + ": its strips are not contiguous");
    end += counts[s];
  }
  if (end - offsets[0] != std::uint64_t(page_bytes)) {
    file.fail(layout + ": its first image holds " + std::to_string(end - offsets[0]) +
              " bytes, expected " + std::to_string(page_bytes));
  }
  const std::uint64_t first = offsets[0];
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec || size < first + std::uint64_t(images * page_bytes)) {
    file.fail(layout + ": the file ends after " +
              std::to_string(ec || size < first ? 0 : (size - first) / page_bytes) +
              " images, expected " + std::to_string(images) + " (truncated?)");
  }

  std::ifstream in(path, std::ios::binary);
  const std::int64_t row_bytes = std::int64_t(page.width) * sample_bytes;
  std::vector<unsigned char> rows(static_cast<std::size_t>(box.ny * row_bytes));
  for (std::int64_t z = box.z0; z < box.z0 + box.nz; ++z) {
    in.seekg(static_cast<std::streamoff>(first + z * page_bytes + box.y0 * row_bytes));
    in.read(reinterpret_cast<char*>(rows.data()), static_cast<std::streamsize>(rows.size()));
    if (!in) file.fail(page_text(z, images) + ": read error");
    if (sample_bytes == 2 && TIFFIsByteSwapped(tif)) {
      TIFFSwabArrayOfShort(reinterpret_cast<std::uint16_t*>(rows.data()),
                           static_cast<tmsize_t>(rows.size() / 2));
    }
    for (std::int64_t y = 0; y < box.ny; ++y) {
      copy_row(rows.data() + y * row_bytes, page, box.x0, box.nx,
               stack.slice(z - box.z0) + y * box.nx);
    }
  }
}

// A header can declare any size: what the file's length can hold bounds it before anything
// is allocated (no TIFF compression packs more than about 1,000:1; deflate's limit is 1,032).
void check_declared_size(TiffFile& file, const std::filesystem::path& path, const TiffPage& page,
                         std::int64_t pages) {
  std::error_code ec;
  const double length = double(std::filesystem::file_size(path, ec));
  const double declared =
      double(page.width) * double(page.height) * double(page.bits / 8) * double(pages);
  if (!ec && declared > 1100 * length) {
    file.fail(std::to_string(pages) + (pages == 1 ? " page" : " pages") + " of " +
              std::to_string(page.width) + "x" + std::to_string(page.height) + " pixels declare " +
              gibibytes(declared) + ", more than any compression holds in the file's " +
              std::to_string(std::int64_t(length)) + " bytes (truncated or corrupt?)");
  }
}

}  // namespace

Stack read_tiff_stack(const std::filesystem::path& path, const std::optional<Region>& region) {
  TiffFile file = TiffFile::open_for_reading(path);
  TIFF* tif = file.get();
  // Walks the chain of page directories; a file cut short breaks it.
  const std::int64_t directories = TIFFNumberOfDirectories(tif);
  if (file.failed()) {
    file.fail("the page chain breaks after page " + std::to_string(directories) +
              ", expected a complete TIFF (file truncated or corrupt?)");
  }
  const TiffPage first = describe_page(file, page_text(0, directories));
  const TiffMetadata meta = read_tiff_metadata(file);

  std::int64_t pages = directories;
  const bool contiguous = directories == 1 && meta.imagej_images > 1;
  if (contiguous) {
    pages = meta.imagej_images;
  } else if (meta.imagej_images > directories) {
    file.fail("ImageJ metadata says " + std::to_string(meta.imagej_images) +
              " images, the file holds " + std::to_string(directories) +
              " pages (file truncated?)");
  }

  check_declared_size(file, path, first, pages);
  const Box box = resolve_region(region, first.width, first.height, pages, path.string());
  Stack stack = allocate_stack(box, first.bits, path.string());
  stack.voxel_size = meta.voxel_size;
  stack.unit = meta.unit;
  if (contiguous) {
    read_imagej_contiguous(file, path, first, pages, box, stack);
    return stack;
  }

  for (std::int64_t z = box.z0; z < box.z0 + box.nz; ++z) {
    const std::string where = page_text(z, pages);
    // Pages before the box are skipped over without reading their data.
    const bool moved = z == box.z0 ? TIFFSetDirectory(tif, static_cast<tdir_t>(z)) == 1
                                   : TIFFReadDirectory(tif) == 1;
    if (!moved || file.failed()) file.fail(where + ": cannot read its directory");
    const TiffPage page = describe_page(file, where);
    if (page.width != first.width || page.height != first.height) {
      file.fail(where + ": " + std::to_string(page.width) + "x" + std::to_string(page.height) +
                " pixels, expected " + std::to_string(first.width) + "x" +
                std::to_string(first.height) + " like page 1");
    }
    if (page.bits != first.bits) {
      file.fail(where + ": " + std::to_string(page.bits) + "-bit, expected " +
                std::to_string(first.bits) + "-bit like page 1");
    }
    read_page(file, page, box, stack.slice(z - box.z0), where);
  }
  return stack;
}

}  // namespace granmem::stack_io
