#pragma once

// Internal: a TIFF file open for reading whose libtiff errors and warnings are captured,
// not printed.

#include <tiffio.h>

#include <filesystem>
#include <memory>
#include <string>

namespace granmem::stack_io {

struct TiffMessages;  // what libtiff reported on one file

class TiffFile {
 public:
  // Throws Error naming the file if it is missing or not a readable TIFF.
  static TiffFile open_for_reading(const std::filesystem::path& path);

  ~TiffFile();
  TiffFile(TiffFile&& other) noexcept;
  TiffFile& operator=(TiffFile&&) = delete;
  TiffFile(const TiffFile&) = delete;
  TiffFile& operator=(const TiffFile&) = delete;

  TIFF* get() const { return tif_; }
  const std::string& name() const;
  // Whether libtiff reported an error (since clear_error()).
  bool failed() const;
  void clear_error();
  // Throws Error "<file>: <what> (<libtiff's message>)", the message when libtiff gave one.
  [[noreturn]] void fail(const std::string& what) const;

 private:
  TiffFile();
  std::unique_ptr<TiffMessages> messages_;  // on the heap: libtiff holds its address
  TIFF* tif_ = nullptr;
};

}  // namespace granmem::stack_io
