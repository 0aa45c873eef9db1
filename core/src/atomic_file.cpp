#include "granmem/core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <string>
#include <system_error>

#include "granmem/core/error.hpp"

namespace granmem {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  static std::atomic<unsigned> counter{0};
  fs::path dir = target_.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw Error(target_.string() + ": cannot write, folder '" + dir.string() + "' does not exist");
  }
  if (fs::is_directory(target_, ec)) {
    throw Error(target_.string() + ": is a folder, expected a file name");
  }
  // Same folder as the target, so that the final rename is atomic.
  temp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++));
}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)), temp_(std::move(other.temp_)), done_(other.done_) {
  other.done_ = true;
}

AtomicFile::~AtomicFile() {
  if (!done_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  if (done_) return;
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec)
    throw Error(target_.string() + ": cannot move the finished file into place: " + ec.message());
  done_ = true;
}

}  // namespace granmem
