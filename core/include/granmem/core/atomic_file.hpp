#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace granmem {

// An output written under a temporary name beside its target and renamed into place by
// commit(), so that a crash or an error never leaves a half-written file under the real
// name and never damages a file that was already there. Uncommitted, the temporary file
// is removed when the object goes; one left by a writer that was killed is removed when
// the next AtomicFile for the same target is made. commit() puts the file on the disk
// (fsync) before renaming it.
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

// A file a command reads or writes, with what names it on the command line ("--out",
// "table"), for the messages.
struct NamedPath {
  std::string name;
  std::filesystem::path path;
};

// Refuses, with one Error, an output that is one of the inputs (the same file by any path,
// link or hard link: writing it would destroy the input), two outputs that are one file,
// and an output whose folder does not exist or cannot be written. Called before any work, so that a
// mistyped command line neither runs for nothing nor damages anything.
void check_outputs(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

}  // namespace granmem
