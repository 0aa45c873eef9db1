// Writes stacks as ImageJ-style TIFF: the first page directory with ImageJ's description,
// then the image data of all pages one after the other, then the other directories.
// ImageJ reads a stack with "images=N" as N images stored contiguously behind the first
// page's data and ignores the other directories, so the data must be laid out that way
// (libtiff interleaves data and directories); other readers follow the directories.
#include <cmath>
#include <cstring>
#include <fstream>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"
#include "stack_formats.hpp"
#include "tiff_metadata.hpp"

namespace granmem::stack_io {
namespace {

enum TagType : std::uint16_t { kAscii = 2, kShort = 3, kLong = 4, kRational = 5, kLong8 = 16 };

bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

// Little-endian bytes, whatever the machine ("II" files).
void put(std::vector<unsigned char>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i)
    out.push_back(static_cast<unsigned char>(value >> (8 * i)));
}

struct Entry {
  std::uint16_t tag;
  TagType type;
  std::uint64_t count;
  std::vector<unsigned char> value;  // count values, little-endian
};

Entry numbers(std::uint16_t tag, TagType type, const std::vector<std::uint64_t>& values) {
  Entry e{tag, type, values.size(), {}};
  const int bytes = type == kShort ? 2 : type == kLong ? 4 : 8;
  for (std::uint64_t v : values)
    put(e.value, v, bytes);
  return e;
}

Entry text(std::uint16_t tag, const std::string& s) {
  Entry e{tag, kAscii, s.size() + 1, {s.begin(), s.end()}};
  e.value.push_back(0);
  return e;
}

// The closest fraction with 32-bit numerator and denominator (continued fractions), so
// that ImageJ, which reads rationals as double, gets the size that was written.
Entry rational(std::uint16_t tag, double value) {
  std::uint64_t p0 = 0, q0 = 1, p1 = 1, q1 = 0;
  double x = value;
  for (int i = 0; i < 64; ++i) {
    const double a = std::floor(x);
    if (a > 4294967295.0) break;
    const std::uint64_t ai = static_cast<std::uint64_t>(a);
    const std::uint64_t p2 = ai * p1 + p0, q2 = ai * q1 + q0;
    if (p2 > 4294967295u || q2 > 4294967295u) break;
    p0 = p1, q0 = q1, p1 = p2, q1 = q2;
    if (x - a < 1e-12 || std::abs(double(p1) / double(q1) - value) <= 1e-15 * value) break;
    x = 1.0 / (x - a);
  }
  if (q1 == 0) p1 = 4294967295u, q1 = 1;
  Entry e{tag, kRational, 1, {}};
  put(e.value, p1, 4);
  put(e.value, q1, 4);
  return e;
}

// The layout of classic TIFF or BigTIFF.
struct Format {
  bool big;
  int header_bytes() const { return big ? 16 : 8; }
  int count_bytes() const { return big ? 8 : 2; }
  int entry_bytes() const { return big ? 20 : 12; }
  int offset_bytes() const { return big ? 8 : 4; }  // also the room for a value in an entry
};

std::uint64_t even(std::uint64_t n) {
  return n + (n & 1);
}

// The bytes a directory and its out-of-line values take.
std::uint64_t directory_bytes(const std::vector<Entry>& entries, const Format& f) {
  std::uint64_t n = f.count_bytes() + entries.size() * f.entry_bytes() + f.offset_bytes();
  for (const Entry& e : entries) {
    if (e.value.size() > std::size_t(f.offset_bytes())) n += even(e.value.size());
  }
  return n;
}

// A directory placed at `offset`, its long values right behind it; `next`: the offset of
// the next directory, 0 for the last.
std::vector<unsigned char> encode_directory(const std::vector<Entry>& entries, const Format& f,
                                            std::uint64_t offset, std::uint64_t next) {
  std::vector<unsigned char> out, values;
  std::uint64_t values_at =
      offset + f.count_bytes() + entries.size() * f.entry_bytes() + f.offset_bytes();
  put(out, entries.size(), f.count_bytes());
  for (const Entry& e : entries) {
    put(out, e.tag, 2);
    put(out, e.type, 2);
    put(out, e.count, f.big ? 8 : 4);
    if (e.value.size() <= std::size_t(f.offset_bytes())) {
      out.insert(out.end(), e.value.begin(), e.value.end());
      out.insert(out.end(), f.offset_bytes() - e.value.size(), 0);
    } else {
      put(out, values_at + values.size(), f.offset_bytes());
      values.insert(values.end(), e.value.begin(), e.value.end());
      if (values.size() & 1) values.push_back(0);
    }
  }
  put(out, next, f.offset_bytes());
  out.insert(out.end(), values.begin(), values.end());
  return out;
}

struct PageLayout {
  std::int64_t row_bytes, page_bytes, rows_per_strip, strips;
};

// The directory of page z whose data start at `data`.
std::vector<Entry> page_entries(const Stack& stack, const PageLayout& layout, const Format& f,
                                std::int64_t z, std::uint64_t data,
                                const std::string& description) {
  std::vector<std::uint64_t> offsets, counts;
  for (std::int64_t s = 0; s < layout.strips; ++s) {
    const std::int64_t rows = std::min(layout.rows_per_strip, stack.ny - s * layout.rows_per_strip);
    offsets.push_back(data + s * layout.rows_per_strip * layout.row_bytes);
    counts.push_back(rows * layout.row_bytes);
  }
  const TagType strile = f.big ? kLong8 : kLong;
  std::vector<Entry> entries = {
      numbers(254, kLong, {0}),  // NewSubfileType: a page of the stack
      numbers(256, kLong, {std::uint64_t(stack.nx)}),
      numbers(257, kLong, {std::uint64_t(stack.ny)}),
      numbers(258, kShort, {std::uint64_t(stack.bits)}),
      numbers(259, kShort, {1}),  // no compression
      numbers(262, kShort, {1}),  // min-is-black grayscale
  };
  if (z == 0) entries.push_back(text(270, description));  // ImageJ reads the first only
  entries.push_back(numbers(273, strile, offsets));
  entries.push_back(numbers(277, kShort, {1}));
  entries.push_back(numbers(278, kLong, {std::uint64_t(layout.rows_per_strip)}));
  entries.push_back(numbers(279, strile, counts));
  if (stack.voxel_size) {
    entries.push_back(rational(282, 1.0 / stack.voxel_size->x()));  // pixels per unit
    entries.push_back(rational(283, 1.0 / stack.voxel_size->y()));
  }
  entries.push_back(numbers(284, kShort, {1}));  // one plane of samples
  if (stack.voxel_size) {
    // ImageJ's choice: centimetres as such, other units as "no unit" (the description says).
    entries.push_back(numbers(296, kShort, {stack.unit == "cm" ? 3u : 1u}));
  }
  entries.push_back(numbers(339, kShort, {1}));  // unsigned integers
  return entries;
}

void check_writable(const Stack& stack, const std::string& name) {
  if (stack.nx <= 0 || stack.ny <= 0 || stack.nz <= 0) {
    throw Error(name + ": cannot write an empty stack (" + std::to_string(stack.nx) + "x" +
                std::to_string(stack.ny) + "x" + std::to_string(stack.nz) + " voxels)");
  }
  if (stack.nx > 4294967295 || stack.ny > 4294967295) {
    throw Error(name + ": slices of " + std::to_string(stack.nx) + "x" + std::to_string(stack.ny) +
                " voxels, more than TIFF holds");
  }
  if (stack.voxels.size() != static_cast<std::size_t>(stack.nx * stack.ny * stack.nz)) {
    throw Error(name + ": the stack holds " + std::to_string(stack.voxels.size()) +
                " voxels, expected nx*ny*nz = " + std::to_string(stack.nx * stack.ny * stack.nz));
  }
  if (stack.bits != 8 && stack.bits != 16) {
    throw Error(name + ": " + std::to_string(stack.bits) + "-bit stack, expected 8 or 16 bits");
  }
  if (stack.voxel_size) {
    if (!is_physical_length_unit(stack.unit)) {
      throw Error(name + ": voxel size in '" + stack.unit + "', expected m, cm, mm or um");
    }
    for (int a = 0; a < 3; ++a) {
      const double v = (*stack.voxel_size)[a];
      if (!std::isfinite(v) || v <= 0) {
        throw Error(name + ": voxel size " + shortest_text(v) + " " + stack.unit +
                    ", expected a positive size");
      }
    }
  }
  if (stack.bits == 8) {
    for (std::size_t i = 0; i < stack.voxels.size(); ++i) {
      if (stack.voxels[i] > 255) {
        const std::int64_t at = static_cast<std::int64_t>(i);
        throw Error(name + ": voxel (" + std::to_string(at % stack.nx) + ", " +
                    std::to_string(at / stack.nx % stack.ny) + ", " +
                    std::to_string(at / (stack.nx * stack.ny)) + ") is " +
                    std::to_string(stack.voxels[i]) + ", more than an 8-bit stack holds");
      }
    }
  }
}

}  // namespace

void write_tiff_stack(const Stack& stack, const std::filesystem::path& path, TiffFormat format) {
  const std::string name = path.string();
  check_writable(stack, name);

  PageLayout layout{};
  layout.row_bytes = stack.nx * (stack.bits / 8);
  layout.page_bytes = layout.row_bytes * stack.ny;
  // Strips of about 128 KiB, so that a reader of a few rows reads little more.
  layout.rows_per_strip = std::clamp<std::int64_t>(131072 / layout.row_bytes, 1, stack.ny);
  layout.strips = (stack.ny + layout.rows_per_strip - 1) / layout.rows_per_strip;
  const std::string description = imagej_description(stack);

  // Offsets of everything, for classic TIFF first; BigTIFF if they pass 4 GB.
  Format f{format == TiffFormat::big};
  std::vector<std::uint64_t> directory_at(static_cast<std::size_t>(stack.nz));
  std::uint64_t data_at = 0, file_bytes = 0;
  for (;;) {
    directory_at[0] = f.header_bytes();
    data_at = even(directory_at[0] +
                   directory_bytes(page_entries(stack, layout, f, 0, 0, description), f));
    std::uint64_t at = even(data_at + std::uint64_t(stack.nz * layout.page_bytes));
    for (std::int64_t z = 1; z < stack.nz; ++z) {
      directory_at[z] = at;
      at += directory_bytes(page_entries(stack, layout, f, z, 0, description), f);
    }
    file_bytes = at;
    if (f.big || file_bytes <= 4294967295u) break;
    if (format == TiffFormat::classic) {
      throw Error(name + ": " + std::to_string(file_bytes) +
                  " bytes do not fit in a classic TIFF, expected at most 4 GB");
    }
    f.big = true;
  }

  AtomicFile atomic(path);
  std::ofstream out(atomic.temp_path(), std::ios::binary);
  if (!out) throw Error(name + ": cannot create the file");
  const auto write = [&](const void* data, std::size_t bytes) {
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    if (!out) throw Error(name + ": writing the TIFF file failed (disk full?)");
  };
  const auto write_directory = [&](std::int64_t z) {
    const std::uint64_t next = z + 1 < stack.nz ? directory_at[z + 1] : 0;
    const auto bytes = encode_directory(
        page_entries(stack, layout, f, z, data_at + z * layout.page_bytes, description), f,
        directory_at[z], next);
    write(bytes.data(), bytes.size());
  };

  std::vector<unsigned char> header = {'I', 'I'};
  if (f.big) {
    put(header, 43, 2);
    put(header, 8, 2);  // bytes per offset
    put(header, 0, 2);
    put(header, directory_at[0], 8);
  } else {
    put(header, 42, 2);
    put(header, directory_at[0], 4);
  }
  write(header.data(), header.size());
  write_directory(0);
  const unsigned char zero[8] = {};
  write(zero, data_at - std::uint64_t(out.tellp()));

  // The image data, little-endian, one page at a time.
  const bool swap = !host_is_little_endian();
  std::vector<unsigned char> page(static_cast<std::size_t>(layout.page_bytes));
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    const std::uint16_t* v = stack.slice(z);
    const std::size_t n = static_cast<std::size_t>(stack.nx * stack.ny);
    if (stack.bits == 8) {
      for (std::size_t i = 0; i < n; ++i)
        page[i] = static_cast<unsigned char>(v[i]);
    } else if (!swap) {
      std::memcpy(page.data(), v, 2 * n);
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        page[2 * i] = static_cast<unsigned char>(v[i]);
        page[2 * i + 1] = static_cast<unsigned char>(v[i] >> 8);
      }
    }
    write(page.data(), page.size());
  }
  if (stack.nz > 1) write(zero, directory_at[1] - std::uint64_t(out.tellp()));
  for (std::int64_t z = 1; z < stack.nz; ++z)
    write_directory(z);

  out.close();
  if (!out) throw Error(name + ": writing the TIFF file failed (disk full?)");
  atomic.commit();
}

}  // namespace granmem::stack_io
