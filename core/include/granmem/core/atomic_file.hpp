#pragma once

#include <filesystem>

namespace granmem {

// An output written under a temporary name beside its target and renamed into place by
// commit(), so that a crash or an error never leaves a half-written file under the real
// name and never damages a file that was already there. Uncommitted, the temporary file
// is removed when the object goes.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&&) = delete;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool done_ = false;
};

}  // namespace granmem
