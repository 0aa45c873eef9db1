#include "tiff_file.hpp"

#include <cstdarg>
#include <cstdio>
#include <system_error>

#include "granmem/core/error.hpp"

namespace granmem::stack_io {

struct TiffMessages {
  std::string name;       // the file as our messages name it
  std::string path_text;  // the path libtiff puts into its own messages
  std::string error;      // libtiff's first error since clear_error()
  bool failed = false;
};

namespace {

// libtiff's text on one line, without the file name (our message leads with it).
std::string format_message(const char* fmt, va_list ap, const std::string& path_text) {
  char buffer[1024];
  std::vsnprintf(buffer, sizeof buffer, fmt, ap);
  std::string text = buffer;
  if (!path_text.empty()) {
    const std::string prefix = path_text + ": ";
    for (std::size_t at; (at = text.find(prefix)) != std::string::npos;)
      text.erase(at, prefix.size());
  }
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

// Per-file handlers: returning 1 keeps libtiff from calling its process-wide handlers,
// which print to stderr by default.
int capture_error(TIFF*, void* user_data, const char*, const char* fmt, va_list ap) {
  auto* messages = static_cast<TiffMessages*>(user_data);
  if (!messages->failed) messages->error = format_message(fmt, ap, messages->path_text);
  messages->failed = true;
  return 1;
}
int ignore_warning(TIFF*, void*, const char*, const char*, va_list) {
  return 1;  // unknown private tags and the like: nothing the caller must know
}

// A few libtiff code paths report through the process-wide handlers only; those messages
// are kept per thread and used when the file's own handler caught nothing.
thread_local std::string global_error;

void capture_global_error(const char*, const char* fmt, va_list ap) {
  if (global_error.empty()) global_error = format_message(fmt, ap, "");
}
void ignore_global_warning(const char*, const char*, va_list) {}

void install_global_handlers() {
  static const bool done = [] {
    TIFFSetErrorHandler(capture_global_error);
    TIFFSetWarningHandler(ignore_global_warning);
    return true;
  }();
  (void)done;
}

// Opens with the per-file handlers; `messages` must outlive the TIFF handle.
TIFF* open_with_handlers(const std::filesystem::path& path, const char* mode,
                         TiffMessages& messages) {
  install_global_handlers();
  global_error.clear();
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, capture_error, &messages);
  TIFFOpenOptionsSetWarningHandlerExtR(options, ignore_warning, &messages);
  TIFF* tif = TIFFOpenExt(path.c_str(), mode, options);
  TIFFOpenOptionsFree(options);
  return tif;
}

}  // namespace

TiffFile::TiffFile() : messages_(std::make_unique<TiffMessages>()) {}

TiffFile TiffFile::open_for_reading(const std::filesystem::path& path) {
  TiffFile file;
  file.messages_->name = path.string();
  file.messages_->path_text = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path.string() + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(path.string() + ": not a regular file, expected a TIFF file");
  }
  // 'm': read through the file instead of mapping it, so that a file truncated under us
  // gives a read error rather than a bus error.
  file.tif_ = open_with_handlers(path, "rm", *file.messages_);
  if (!file.tif_) file.fail("cannot open as TIFF, expected a TIFF file (truncated or corrupt?)");
  return file;
}

TiffFile::~TiffFile() {
  if (tif_) TIFFClose(tif_);
}

TiffFile::TiffFile(TiffFile&& other) noexcept
    : messages_(std::move(other.messages_)), tif_(other.tif_) {
  other.tif_ = nullptr;
}

const std::string& TiffFile::name() const {
  return messages_->name;
}

bool TiffFile::failed() const {
  return messages_->failed;
}

void TiffFile::clear_error() {
  messages_->failed = false;
  messages_->error.clear();
}

void TiffFile::fail(const std::string& what) const {
  std::string detail = messages_->failed ? messages_->error : global_error;
  global_error.clear();
  throw Error(messages_->name + ": " + what + (detail.empty() ? "" : " (" + detail + ")"));
}

}  // namespace granmem::stack_io
