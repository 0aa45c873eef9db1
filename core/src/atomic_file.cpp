#include "granmem/core/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>

#include "granmem/core/error.hpp"

namespace granmem {

namespace fs = std::filesystem;

namespace {

// Temporaries of `target` whose writer is gone (killed, or the machine stopped): a kill -9
// leaves them, as large as the run, and nothing else would remove them. One of a running
// process (this one, or another writing the same target) is kept.
void remove_orphaned_temporaries(const fs::path& dir, const fs::path& target) {
  const std::string prefix = "." + target.filename().string() + ".tmp-";
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const std::size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos) continue;
    if (rest.find_first_not_of("0123456789") != dash) continue;
    const long pid = std::stol(rest.substr(0, dash));
    if (pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH) fs::remove(e.path(), ec);
  }
}

// The file's data, or a folder's entries, on the disk (not only in the page cache).
void sync_to_disk(const fs::path& path, bool folder) {
  const int fd = ::open(path.c_str(), folder ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

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
  remove_orphaned_temporaries(dir, target_);
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
  // On the disk before the rename, so that a machine stopping after it finds the whole
  // file under the name, and the rename itself after it.
  sync_to_disk(temp_, false);
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec)
    throw Error(target_.string() + ": cannot move the finished file into place: " + ec.message());
  done_ = true;
  const fs::path dir = target_.parent_path();
  sync_to_disk(dir.empty() ? fs::path(".") : dir, true);
}

namespace {

// Whether a and b name one file: by identity where both exist, else by their normal form.
bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && ca == cb;
}

std::string named(const NamedPath& p) {
  return p.name + " '" + p.path.string() + "'";
}

}  // namespace

void check_outputs(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const NamedPath& out = outputs[k];
    const fs::path folder = out.path.parent_path().empty() ? fs::path(".") : out.path.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
      throw Error(named(out) + ": folder '" + folder.string() + "' does not exist");
    }
    if (::access(folder.c_str(), W_OK) != 0) {
      throw Error(named(out) + ": folder '" + folder.string() + "' is not writable");
    }
    for (const NamedPath& in : inputs) {
      if (same_file(out.path, in.path)) {
        throw Error(named(out) + ": is the input " + named(in) +
                    ", which writing it would destroy; choose another name");
      }
    }
    for (std::size_t m = 0; m < k; ++m) {
      if (same_file(out.path, outputs[m].path)) {
        throw Error(named(out) + " and " + named(outputs[m]) + " are one file");
      }
    }
  }
}

}  // namespace granmem
