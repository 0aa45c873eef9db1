#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/table.hpp"

// A thin layer over the HDF5 C library: owned identifiers, whole-dataset and per-frame
// reads and writes with a `unit` attribute on datasets that have one, fixed-length string
// attributes (as H5MD requires; both kinds are read), and messages that name the file and
// the dataset. HDF5's own error printing is switched off; failures throw Error.
namespace granmem::h5 {

class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  void reset();
  hid_t release();  // the id, no longer closed by this handle

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// An open file and its name, which every message about it carries.
class File {
 public:
  static File create(const std::filesystem::path& path);  // new file, truncating
  static File create(const AtomicFile& file);             // its temporary, named by its target
  static File open(const std::filesystem::path& path);    // read-only; Error if not HDF5
  static File open_for_writing(const std::filesystem::path& path);  // an existing file
  void flush();  // everything written so far on disk: the file is complete as it stands
  hid_t id() const { return handle_.get(); }
  const std::string& name() const { return name_; }
  void close();  // flushes; throws Error if the data could not be written

 private:
  static File create(const std::filesystem::path& path, const std::string& name);
  Handle handle_;
  std::string name_;
};

bool exists(hid_t loc, const std::string& path);
void remove(hid_t loc, const std::string& path);          // unlinks a group or dataset if there
Handle create_group(hid_t loc, const std::string& path);  // intermediate groups too
Handle open_group(const File& file, const std::string& path);
Handle open_dataset(const File& file, const std::string& path);
std::vector<hsize_t> shape(hid_t dataset);
std::string shape_text(const std::vector<hsize_t>& dims);  // "[3,10,3]"

// Whole datasets of double, int64 or uint8, with a `unit` attribute unless `unit` is empty.
template <class T>
void write(hid_t loc, const std::string& name, const T* data, const std::vector<hsize_t>& dims,
           const std::string& unit);
// Reads a whole dataset, converting the stored type to T.
template <class T>
std::vector<T> read(const File& file, const std::string& path);

// A dataset that grows by one frame at a time along its first axis: [T, frame_dims...].
template <class T>
Handle create_frames(hid_t loc, const std::string& name, const std::vector<hsize_t>& frame_dims,
                     const std::string& unit);
template <class T>
void append_frame(hid_t dataset, const T* data);
// Keeps the first `frames` frames of a [T, ...] dataset made by create_frames.
void truncate_frames(hid_t dataset, hsize_t frames);
// Reads frame `t` of a [T, ...] dataset into `data` (size of one frame).
template <class T>
void read_frame(const File& file, hid_t dataset, const std::string& path, hsize_t t, T* data);

void write_attribute(hid_t obj, const std::string& name, const std::string& value);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values);
void write_attribute(hid_t obj, const std::string& name, const std::vector<int>& values);
std::optional<std::string> read_string_attribute(hid_t obj, const std::string& name);
// A scalar numeric attribute (an H5MD `offset`), as a double; none if absent or not a number.
std::optional<double> read_number_attribute(hid_t obj, const std::string& name);
std::vector<std::string> attribute_names(hid_t obj);
std::vector<std::string> member_names(hid_t group);

// Every dataset under `group`, depth first in name order, with its shape and unit.
struct DatasetInfo {
  std::string path;
  std::vector<hsize_t> dims;
  std::string unit;
};
std::vector<DatasetInfo> list_datasets(const File& file, const std::string& group = "/");

// A table as a group of 1-D column datasets (in column order, via `columns` attribute).
void write_table(hid_t loc, const std::string& group, const Table& table);
Table read_table(const File& file, const std::string& group);

}  // namespace granmem::h5
