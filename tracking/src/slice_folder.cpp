// Stacks stored as one image per slice (TIFF or PNG) in a folder, in natural name order.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstring>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "granmem/core/error.hpp"
#include "stack_formats.hpp"
#include "tiff_file.hpp"
#include "tiff_metadata.hpp"
#include "tiff_page.hpp"

namespace granmem::stack_io {
namespace {

namespace fs = std::filesystem;

bool is_digit(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) != 0;
}

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// By content, not by name: a PNG's eight-byte signature.
bool is_png(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char head[8] = {};
  return in.read(head, 8) && std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0;
}
// A PNG cut short (an interrupted copy) lacks its closing IEND chunk. Checked before
// decoding so that the error is ours alone: libpng prints its own to stderr.
bool png_is_complete(const fs::path& p) {
  static const std::string iend("\0\0\0\0IEND\xAE\x42\x60\x82", 12);
  std::ifstream in(p, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  const std::streamoff tail = std::min<std::streamoff>(size, 256);
  std::string bytes(static_cast<std::size_t>(tail), '\0');
  in.seekg(size - tail);
  return in.read(bytes.data(), tail) && bytes.find(iend) != std::string::npos;
}
bool is_slice_image(const fs::path& p) {
  const std::string ext = lower_extension(p);
  return ext == ".tif" || ext == ".tiff" || ext == ".png";
}

struct SliceShape {
  std::int64_t width = 0, height = 0;
  int bits = 8;
};

std::string shape_text(const SliceShape& s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height) + " pixels of " +
         std::to_string(s.bits) + " bits";
}

// The checks every slice passes before its pixels are copied: the shape of the first.
void check_like_first(const SliceShape& shape, const SliceShape* first, const fs::path& file,
                      const std::string& where, const fs::path& first_file) {
  if (!first) return;
  if (shape.width != first->width || shape.height != first->height || shape.bits != first->bits) {
    throw Error(file.string() + ": " + where + ": " + shape_text(shape) + ", expected " +
                shape_text(*first) + " like " + first_file.filename().string());
  }
}

// Reads one TIFF slice: its shape, its metadata when `meta` is given, and with `out` the
// box's window of its pixels.
SliceShape read_tiff_slice(const fs::path& file, const std::string& where, const SliceShape* first,
                           const fs::path& first_file, const Box* box, std::uint16_t* out,
                           TiffMetadata* meta) {
  TiffFile tiff = TiffFile::open_for_reading(file);
  const tdir_t pages = TIFFNumberOfDirectories(tiff.get());
  if (tiff.failed()) {
    tiff.fail(where + ": its page chain breaks, expected a complete TIFF (truncated or corrupt?)");
  }
  if (pages != 1) {
    tiff.fail(where + ": " + std::to_string(pages) +
              " pages, expected one image per slice file (read a multi-page TIFF as a file, "
              "not in a folder)");
  }
  const TiffPage page = describe_page(tiff, where);
  const SliceShape shape{page.width, page.height, page.bits};
  check_like_first(shape, first, file, where, first_file);
  if (meta) *meta = read_tiff_metadata(tiff);
  if (out) read_page(tiff, page, *box, out, where);
  return shape;
}

SliceShape read_png_slice(const fs::path& file, const std::string& where, const SliceShape* first,
                          const fs::path& first_file, const Box* box, std::uint16_t* out) {
  if (!png_is_complete(file)) {
    throw Error(file.string() + ": " + where +
                ": no IEND chunk at its end, expected a complete PNG image (truncated?)");
  }
  const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    throw Error(file.string() + ": " + where +
                ": cannot decode, expected a PNG image (truncated or corrupt?)");
  }
  if (image.channels() != 1) {
    throw Error(file.string() + ": " + where + ": " + std::to_string(image.channels()) +
                " channels (colour or alpha), expected a grayscale image");
  }
  if (image.depth() != CV_8U && image.depth() != CV_16U) {
    throw Error(file.string() + ": " + where + ": expected 8- or 16-bit grayscale");
  }
  const SliceShape shape{image.cols, image.rows, image.depth() == CV_8U ? 8 : 16};
  check_like_first(shape, first, file, where, first_file);
  if (out) {
    for (std::int64_t y = 0; y < box->ny; ++y) {
      std::uint16_t* row = out + y * box->nx;
      const int r = static_cast<int>(box->y0 + y);
      if (shape.bits == 8) {
        const std::uint8_t* in = image.ptr<std::uint8_t>(r) + box->x0;
        std::copy(in, in + box->nx, row);
      } else {
        const std::uint16_t* in = image.ptr<std::uint16_t>(r) + box->x0;
        std::copy(in, in + box->nx, row);
      }
    }
  }
  return shape;
}

SliceShape read_slice(const fs::path& file, const std::string& where, const SliceShape* first,
                      const fs::path& first_file, const Box* box, std::uint16_t* out,
                      TiffMetadata* meta) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw Error(file.string() + ": no such file");
  if (is_png(file)) return read_png_slice(file, where, first, first_file, box, out);
  return read_tiff_slice(file, where, first, first_file, box, out, meta);
}

}  // namespace

Stack read_slices(const std::vector<fs::path>& slices, const std::optional<Region>& region,
                  const std::string& source) {
  const std::int64_t n = static_cast<std::int64_t>(slices.size());
  const auto where = [n](std::int64_t z) {
    return "slice " + std::to_string(z + 1) + " of " + std::to_string(n);
  };
  // The first slice sets the shape (and, as a TIFF, the voxel size) for all.
  TiffMetadata meta;
  const SliceShape first = read_slice(slices[0], where(0), nullptr, {}, nullptr, nullptr, &meta);
  const Box box = resolve_region(region, first.width, first.height, n, source);
  Stack stack = allocate_stack(box, first.bits, source);
  stack.voxel_size = meta.voxel_size;
  stack.unit = meta.unit;

  // Slices decode independently; the error of the first bad slice (in z) is reported.
  std::atomic<bool> failed{false};
  std::int64_t error_z = std::numeric_limits<std::int64_t>::max();
  std::string error;
#pragma omp parallel for schedule(dynamic)
  for (std::int64_t z = box.z0; z < box.z0 + box.nz; ++z) {
    if (failed) continue;
    std::string message;
    try {
      read_slice(slices[z], where(z), &first, slices[0], &box, stack.slice(z - box.z0), nullptr);
    } catch (const Error& e) {
      message = e.what();
    } catch (const std::exception& e) {  // OpenCV's cv::Exception
      message = slices[z].string() + ": " + where(z) + ": cannot read: " + e.what();
    }
    if (!message.empty()) {
#pragma omp critical(granmem_slice_error)
      {
        if (z < error_z) {
          error_z = z;
          error = message;
        }
      }
      failed = true;
    }
  }
  if (!error.empty()) {
    for (char& c : error) {
      if (c == '\n') c = ' ';
    }
    throw Error(error);
  }
  return stack;
}

Stack read_slice_folder(const fs::path& folder, const std::optional<Region>& region) {
  std::vector<fs::path> slices;
  std::size_t files = 0;
  try {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
      // Hidden files: editors' backups, unfinished atomic writes, macOS "._" companions.
      if (entry.path().filename().string().rfind('.', 0) == 0) continue;
      std::error_code ec;
      if (!entry.is_regular_file(ec)) continue;
      ++files;
      if (is_slice_image(entry.path())) slices.push_back(entry.path());
    }
  } catch (const fs::filesystem_error& e) {
    throw Error(folder.string() + ": cannot list the folder (" + e.code().message() + ")");
  }
  if (files == 0) {
    throw Error(folder.string() + ": empty folder, expected slice images (.tif, .tiff or .png)");
  }
  if (slices.empty()) {
    throw Error(folder.string() + ": none of its " + std::to_string(files) +
                " files is a slice image, expected .tif, .tiff or .png files");
  }
  std::sort(slices.begin(), slices.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return read_slices(slices, region, folder.string());
}

}  // namespace granmem::stack_io

namespace granmem {

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (stack_io::is_digit(a[i]) && stack_io::is_digit(b[j])) {
      // Numbers compare by value: without leading zeros, the shorter is the smaller.
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && stack_io::is_digit(a[i_end]))
        ++i_end;
      while (j_end < b.size() && stack_io::is_digit(b[j_end]))
        ++j_end;
      std::size_t ia = i, jb = j;
      while (ia + 1 < i_end && a[ia] == '0')
        ++ia;
      while (jb + 1 < j_end && b[jb] == '0')
        ++jb;
      if (i_end - ia != j_end - jb) return i_end - ia < j_end - jb;
      const int c = a.compare(ia, i_end - ia, b, jb, j_end - jb);
      if (c != 0) return c < 0;
      i = i_end;
      j = j_end;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i;
    ++j;
  }
  if ((i < a.size()) != (j < b.size())) return j < b.size();  // a prefix comes first
  return a < b;  // equal but for leading zeros: a fixed order all the same
}

}  // namespace granmem
