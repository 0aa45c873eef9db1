#include "granmem/core/hdf5.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "granmem/core/error.hpp"

namespace granmem::h5 {
namespace {

// HDF5 prints its error stack to stderr by default; granmem reports one line instead. The
// setting is per thread in a thread-safe HDF5 (calibrate writes runs from several).
void quiet_hdf5() {
  // Once per process, before the library starts: no clean-up at exit. After a failed
  // close (a full disk) HDF5 keeps the file in its tables and its exit handler crashes
  // closing it again (HDF5 1.10); the operating system frees everything anyway.
  static const bool once = [] {
    H5dont_atexit();
    return true;
  }();
  (void)once;
  thread_local const bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

template <class T>
struct Type;
template <>
struct Type<double> {
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
};
template <>
struct Type<std::int64_t> {
  static hid_t memory() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
};
template <>
struct Type<std::uint8_t> {
  static hid_t memory() { return H5T_NATIVE_UINT8; }
  static hid_t file() { return H5T_STD_U8LE; }
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw Error(what);
}
hid_t check_id(hid_t id, const std::string& what) {
  if (id < 0) throw Error(what);
  return id;
}

Handle dataspace(const std::vector<hsize_t>& dims, const std::vector<hsize_t>* max = nullptr) {
  if (dims.empty()) return Handle(check_id(H5Screate(H5S_SCALAR), "HDF5: dataspace"), H5Sclose);
  return Handle(check_id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(),
                                          max ? max->data() : nullptr),
                         "HDF5: dataspace"),
                H5Sclose);
}

// The memory type for reading variable-length strings of the file's character set (HDF5
// does not convert between ASCII and UTF-8).
Handle string_type(H5T_cset_t cset) {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), cset);
  return t;
}

// Strings are written fixed-length and null-terminated, as H5MD 1.1 requires of its
// attributes: ASCII where every byte is, else UTF-8.
Handle fixed_string_type(const std::vector<std::string>& values) {
  std::size_t longest = 0;
  bool ascii = true;
  for (const std::string& v : values) {
    longest = std::max(longest, v.size());
    for (unsigned char c : v)
      ascii = ascii && c < 0x80;
  }
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), longest + 1);
  H5Tset_strpad(t.get(), H5T_STR_NULLTERM);
  H5Tset_cset(t.get(), ascii ? H5T_CSET_ASCII : H5T_CSET_UTF8);
  return t;
}

hsize_t elements(const std::vector<hsize_t>& dims) {
  return std::accumulate(dims.begin(), dims.end(), hsize_t{1}, std::multiplies<>());
}

std::vector<std::string> read_string_list_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (attr.get() < 0) return {};
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING) return {};
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<std::string> out;
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle mem = string_type(H5Tget_cset(type.get()));
    std::vector<char*> ptrs(static_cast<std::size_t>(n), nullptr);
    check(H5Aread(attr.get(), mem.get(), ptrs.data()), "HDF5: cannot read attribute " + name);
    for (char* p : ptrs) {
      out.emplace_back(p ? p : "");
      H5free_memory(p);
    }
  } else {
    const std::size_t size = H5Tget_size(type.get());
    std::vector<char> buf(size * static_cast<std::size_t>(n) + 1, '\0');
    check(H5Aread(attr.get(), type.get(), buf.data()), "HDF5: cannot read attribute " + name);
    const bool space_padded = H5Tget_strpad(type.get()) == H5T_STR_SPACEPAD;
    for (hssize_t i = 0; i < n; ++i) {
      const char* p = buf.data() + static_cast<std::size_t>(i) * size;
      std::string s(p, strnlen(p, size));
      if (space_padded) s.erase(s.find_last_not_of(' ') + 1);
      out.push_back(std::move(s));
    }
  }
  return out;
}

}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    reset();
    id_ = o.id_;
    close_ = o.close_;
    o.id_ = -1;
  }
  return *this;
}

void Handle::reset() {
  if (id_ >= 0 && close_) close_(id_);
  id_ = -1;
}

hid_t Handle::release() {
  const hid_t id = id_;
  id_ = -1;
  return id;
}

File File::create(const std::filesystem::path& path) {
  return create(path, path.string());
}

File File::create(const std::filesystem::path& path, const std::string& name) {
  quiet_hdf5();
  File f;
  f.name_ = name;
  f.handle_ = Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (f.handle_.get() < 0) throw Error(f.name_ + ": cannot create HDF5 file");
  return f;
}

File File::create(const AtomicFile& file) {
  return create(file.temp_path(), file.target().string());
}

File File::open(const std::filesystem::path& path) {
  quiet_hdf5();
  File f;
  f.name_ = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(f.name_ + ": no such file");
  if (H5Fis_hdf5(f.name_.c_str()) <= 0) {
    throw Error(f.name_ + ": not an HDF5 file (or truncated), expected a granmem/H5MD file");
  }
  f.handle_ = Handle(H5Fopen(f.name_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (f.handle_.get() < 0) throw Error(f.name_ + ": cannot open HDF5 file (damaged?)");
  return f;
}

File File::open_for_writing(const std::filesystem::path& path) {
  File f = open(path);  // the checks and messages of a read
  f.handle_ = Handle();
  f.handle_ = Handle(H5Fopen(f.name_.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  if (f.handle_.get() < 0) throw Error(f.name_ + ": cannot open HDF5 file for writing");
  return f;
}

void File::flush() {
  if (H5Fflush(handle_.get(), H5F_SCOPE_GLOBAL) < 0) {
    throw Error(name_ + ": writing the HDF5 file failed (disk full?)");
  }
}

void File::close() {
  if (handle_.get() < 0) return;
  // Closed once: after a failed close (a full disk) a second H5Fclose of the id crashes.
  const hid_t id = handle_.release();
  const herr_t flushed = H5Fflush(id, H5F_SCOPE_GLOBAL);
  const herr_t closed = H5Fclose(id);
  if (flushed < 0 || closed < 0) throw Error(name_ + ": writing the HDF5 file failed (disk full?)");
}

bool exists(hid_t loc, const std::string& path) {
  quiet_hdf5();
  std::size_t pos = 0;
  while (pos < path.size()) {
    std::size_t next = path.find('/', pos + 1);
    const std::string prefix = path.substr(0, next);
    if (!prefix.empty() && prefix != "/" && H5Lexists(loc, prefix.c_str(), H5P_DEFAULT) <= 0) {
      return false;
    }
    if (next == std::string::npos) break;
    pos = next;
  }
  return true;
}

void remove(hid_t loc, const std::string& path) {
  if (exists(loc, path))
    check(H5Ldelete(loc, path.c_str(), H5P_DEFAULT), "HDF5: cannot remove " + path);
}

Handle create_group(hid_t loc, const std::string& path) {
  quiet_hdf5();
  if (exists(loc, path)) {
    return Handle(check_id(H5Gopen2(loc, path.c_str(), H5P_DEFAULT), "HDF5: open group " + path),
                  H5Gclose);
  }
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  return Handle(check_id(H5Gcreate2(loc, path.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
                         "HDF5: cannot create group " + path),
                H5Gclose);
}

Handle open_group(const File& file, const std::string& path) {
  if (!exists(file.id(), path)) throw Error(file.name() + ": missing group " + path);
  Handle g(H5Gopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Gclose);
  if (g.get() < 0) throw Error(file.name() + ": " + path + " is not a group");
  return g;
}

Handle open_dataset(const File& file, const std::string& path) {
  if (!exists(file.id(), path)) throw Error(file.name() + ": missing dataset " + path);
  Handle d(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.get() < 0) throw Error(file.name() + ": " + path + " is not a dataset");
  return d;
}

std::vector<hsize_t> shape(hid_t dataset) {
  Handle space(H5Dget_space(dataset), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

std::string shape_text(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (std::size_t i = 0; i < dims.size(); ++i)
    s += (i ? "," : "") + std::to_string(dims[i]);
  return s + "]";
}

template <class T>
void write(hid_t loc, const std::string& name, const T* data, const std::vector<hsize_t>& dims,
           const std::string& unit) {
  quiet_hdf5();
  Handle space = dataspace(dims);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  Handle set(check_id(H5Dcreate2(loc, name.c_str(), Type<T>::file(), space.get(), lcpl.get(),
                                 H5P_DEFAULT, H5P_DEFAULT),
                      "HDF5: cannot create dataset " + name),
             H5Dclose);
  if (elements(dims) > 0) {
    check(H5Dwrite(set.get(), Type<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
          "HDF5: cannot write dataset " + name);
  }
  if (!unit.empty()) write_attribute(set.get(), "unit", unit);
}

template <class T>
std::vector<T> read(const File& file, const std::string& path) {
  Handle set = open_dataset(file, path);
  std::vector<T> out(elements(shape(set.get())));
  if (!out.empty() &&
      H5Dread(set.get(), Type<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0) {
    throw Error(file.name() + ": cannot read dataset " + path + " as numbers");
  }
  return out;
}

template <class T>
Handle create_frames(hid_t loc, const std::string& name, const std::vector<hsize_t>& frame_dims,
                     const std::string& unit) {
  quiet_hdf5();
  std::vector<hsize_t> dims{0}, max{H5S_UNLIMITED}, chunk;
  dims.insert(dims.end(), frame_dims.begin(), frame_dims.end());
  max.insert(max.end(), frame_dims.begin(), frame_dims.end());
  // One frame per chunk for per-grain data (a frame is read whole); many for step/time.
  const hsize_t per_frame = elements(frame_dims);
  chunk.push_back(std::clamp<hsize_t>(4096 / std::max<hsize_t>(per_frame, 1), 1, 512));
  for (hsize_t d : frame_dims)
    chunk.push_back(std::max<hsize_t>(d, 1));
  Handle space = dataspace(dims, &max);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  check(H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data()),
        "HDF5: chunking " + name);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  Handle set(check_id(H5Dcreate2(loc, name.c_str(), Type<T>::file(), space.get(), lcpl.get(),
                                 dcpl.get(), H5P_DEFAULT),
                      "HDF5: cannot create dataset " + name),
             H5Dclose);
  if (!unit.empty()) write_attribute(set.get(), "unit", unit);
  return set;
}

template <class T>
void append_frame(hid_t dataset, const T* data) {
  std::vector<hsize_t> dims = shape(dataset);
  const hsize_t t = dims[0];
  dims[0] = t + 1;
  check(H5Dset_extent(dataset, dims.data()), "HDF5: cannot extend dataset");
  std::vector<hsize_t> start(dims.size(), 0), count(dims);
  start[0] = t;
  count[0] = 1;
  Handle file_space(H5Dget_space(dataset), H5Sclose);
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        "HDF5: select frame");
  Handle mem_space = dataspace(count);
  if (elements(count) == 0) return;
  check(H5Dwrite(dataset, Type<T>::memory(), mem_space.get(), file_space.get(), H5P_DEFAULT, data),
        "HDF5: cannot write frame");
}

void truncate_frames(hid_t dataset, hsize_t frames) {
  std::vector<hsize_t> dims = shape(dataset);
  if (dims.empty() || frames > dims[0]) throw Error("HDF5: cannot keep more frames than there are");
  dims[0] = frames;
  check(H5Dset_extent(dataset, dims.data()), "HDF5: cannot shrink dataset");
}

template <class T>
void read_frame(const File& file, hid_t dataset, const std::string& path, hsize_t t, T* data) {
  const std::vector<hsize_t> dims = shape(dataset);
  if (dims.empty() || t >= dims[0]) {
    throw Error(file.name() + ": " + path + " has no frame " + std::to_string(t));
  }
  std::vector<hsize_t> start(dims.size(), 0), count(dims);
  start[0] = t;
  count[0] = 1;
  if (elements(count) == 0) return;
  Handle file_space(H5Dget_space(dataset), H5Sclose);
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        "HDF5: select frame");
  Handle mem_space = dataspace(count);
  if (H5Dread(dataset, Type<T>::memory(), mem_space.get(), file_space.get(), H5P_DEFAULT, data) <
      0) {
    throw Error(file.name() + ": cannot read frame " + std::to_string(t) + " of " + path +
                " (file damaged?)");
  }
}

#define GRANMEM_H5_INSTANTIATE(T)                                                          \
  template void write<T>(hid_t, const std::string&, const T*, const std::vector<hsize_t>&, \
                         const std::string&);                                              \
  template std::vector<T> read<T>(const File&, const std::string&);                        \
  template Handle create_frames<T>(hid_t, const std::string&, const std::vector<hsize_t>&, \
                                   const std::string&);                                    \
  template void append_frame<T>(hid_t, const T*);                                          \
  template void read_frame<T>(const File&, hid_t, const std::string&, hsize_t, T*);
GRANMEM_H5_INSTANTIATE(double)
GRANMEM_H5_INSTANTIATE(std::int64_t)
GRANMEM_H5_INSTANTIATE(std::uint8_t)
#undef GRANMEM_H5_INSTANTIATE

std::optional<double> read_number_attribute(hid_t obj, const std::string& name) {
  quiet_hdf5();
  if (H5Aexists(obj, name.c_str()) <= 0) return std::nullopt;
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  const H5T_class_t c = H5Tget_class(type.get());
  if ((c != H5T_INTEGER && c != H5T_FLOAT) || H5Sget_simple_extent_npoints(space.get()) != 1) {
    return std::nullopt;
  }
  double v = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &v) < 0) return std::nullopt;
  return v;
}

void write_attribute(hid_t obj, const std::string& name, const std::string& value) {
  write_attribute(obj, name, std::vector<std::string>{value});
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values) {
  quiet_hdf5();
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  Handle type = fixed_string_type(values);
  // A single string is a scalar attribute, as h5py and H5MD readers expect.
  Handle space = values.size() == 1 ? dataspace({}) : dataspace({values.size()});
  Handle attr(
      check_id(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
               "HDF5: cannot create attribute " + name),
      H5Aclose);
  const std::size_t size = H5Tget_size(type.get());
  std::vector<char> packed(size * values.size(), '\0');
  for (std::size_t i = 0; i < values.size(); ++i)
    std::copy(values[i].begin(), values[i].end(), packed.begin() + std::ptrdiff_t(i * size));
  check(H5Awrite(attr.get(), type.get(), packed.data()), "HDF5: cannot write attribute " + name);
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<int>& values) {
  quiet_hdf5();
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  Handle space = values.size() == 1 ? dataspace({}) : dataspace({values.size()});
  Handle attr(
      check_id(H5Acreate2(obj, name.c_str(), H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
               "HDF5: cannot create attribute " + name),
      H5Aclose);
  check(H5Awrite(attr.get(), H5T_NATIVE_INT, values.data()),
        "HDF5: cannot write attribute " + name);
}

std::optional<std::string> read_string_attribute(hid_t obj, const std::string& name) {
  quiet_hdf5();
  if (H5Aexists(obj, name.c_str()) <= 0) return std::nullopt;
  std::vector<std::string> values = read_string_list_attribute(obj, name);
  if (values.empty()) return std::nullopt;
  return values.front();
}

std::vector<std::string> attribute_names(hid_t obj) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  H5Aiterate2(
      obj, H5_INDEX_NAME, H5_ITER_INC, &idx,
      [](hid_t, const char* name, const H5A_info_t*, void* out) -> herr_t {
        static_cast<std::vector<std::string>*>(out)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

std::vector<std::string> member_names(hid_t group) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  H5Literate(
      group, H5_INDEX_NAME, H5_ITER_INC, &idx,
      [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
        static_cast<std::vector<std::string>*>(out)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

std::vector<DatasetInfo> list_datasets(const File& file, const std::string& group) {
  std::vector<DatasetInfo> out;
  Handle g = open_group(file, group);
  const std::string prefix = group == "/" ? "/" : group + "/";
  for (const std::string& name : member_names(g.get())) {
    const Handle member(H5Oopen(g.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    const H5I_type_t type = H5Iget_type(member.get());
    if (type == H5I_GROUP) {
      std::vector<DatasetInfo> inner = list_datasets(file, prefix + name);
      out.insert(out.end(), inner.begin(), inner.end());
    } else if (type == H5I_DATASET) {
      // A unit H5MD has a symbol for, or one of granmem's own (voxel, cycle).
      const std::string unit =
          read_string_attribute(member.get(), "unit")
              .value_or(read_string_attribute(member.get(), "granmem_unit").value_or(""));
      out.push_back({prefix + name, shape(member.get()), unit});
    }
  }
  return out;
}

void write_table(hid_t loc, const std::string& group, const Table& table) {
  Handle g = create_group(loc, group);
  std::vector<std::string> order;
  const std::vector<hsize_t> dims{table.rows()};
  for (const Column& c : table.columns()) {
    order.push_back(c.name);
    const std::string unit = c.unit.empty() ? "1" : c.unit;  // dimensionless, said so
    if (c.integer) {
      std::vector<std::int64_t> ints(c.values.size());
      std::transform(c.values.begin(), c.values.end(), ints.begin(),
                     [](double v) { return static_cast<std::int64_t>(v); });
      write(g.get(), c.name, ints.data(), dims, unit);
    } else {
      write(g.get(), c.name, c.values.data(), dims, unit);
    }
  }
  write_attribute(g.get(), "columns", order);
}

Table read_table(const File& file, const std::string& group) {
  Handle g = open_group(file, group);
  std::vector<std::string> order = read_string_list_attribute(g.get(), "columns");
  if (order.empty()) order = member_names(g.get());
  Table table;
  for (const std::string& name : order) {
    const std::string path = group + "/" + name;
    Handle set = open_dataset(file, path);
    Handle type(H5Dget_type(set.get()), H5Tclose);
    const std::string unit = read_string_attribute(set.get(), "unit").value_or("");
    Column& c = table.add(name, unit == "1" ? "" : unit, H5Tget_class(type.get()) == H5T_INTEGER);
    c.values = read<double>(file, path);
  }
  return table;
}

}  // namespace granmem::h5
