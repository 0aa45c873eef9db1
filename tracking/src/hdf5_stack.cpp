// Stacks stored as a 3-D HDF5 dataset in (z, y, x) order, read by hyperslab.
#include <array>
#include <cmath>

#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"
#include "stack_formats.hpp"

namespace granmem::stack_io {
namespace {

std::string type_text(hid_t type) {
  const std::size_t bits = 8 * H5Tget_size(type);
  switch (H5Tget_class(type)) {
    case H5T_INTEGER:
      return std::string(H5Tget_sign(type) == H5T_SGN_NONE ? "unsigned " : "signed ") +
             std::to_string(bits) + "-bit integers";
    case H5T_FLOAT:
      return std::to_string(bits) + "-bit floating-point numbers";
    default:
      return "values that are not numbers";
  }
}

// The dataset to read when none was named: the file's only 3-D dataset.
std::string only_3d_dataset(const h5::File& file) {
  std::vector<std::string> cubes;
  for (const h5::DatasetInfo& d : h5::list_datasets(file)) {
    if (d.dims.size() == 3) cubes.push_back(d.path);
  }
  if (cubes.size() == 1) return cubes[0];
  std::string list;
  for (const std::string& c : cubes)
    list += (list.empty() ? "" : ", ") + c;
  throw Error(file.name() + ": " +
              (cubes.empty() ? std::string("no 3-D dataset, expected one in (z, y, x) order")
                             : "several 3-D datasets (" + list + "), name the one to read"));
}

// "element_size_um": the voxel size in micrometres, (z, y, x), as Fiji's HDF5 plugin and
// ilastik write it.
std::optional<Eigen::Vector3d> element_size(hid_t dataset) {
  if (H5Aexists(dataset, "element_size_um") <= 0) return std::nullopt;
  h5::Handle attribute(H5Aopen(dataset, "element_size_um", H5P_DEFAULT), H5Aclose);
  if (attribute.get() < 0) return std::nullopt;
  h5::Handle space(H5Aget_space(attribute.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 3) return std::nullopt;
  std::array<double, 3> zyx{};
  if (H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, zyx.data()) < 0) return std::nullopt;
  for (double v : zyx) {
    if (!std::isfinite(v) || v <= 0) return std::nullopt;
  }
  return Eigen::Vector3d(zyx[2], zyx[1], zyx[0]);
}

}  // namespace

Stack read_hdf5_stack(const std::filesystem::path& path, const StackReadOptions& options) {
  const h5::File file = h5::File::open(path);
  const std::string name = options.dataset.empty() ? only_3d_dataset(file) : options.dataset;
  const std::string where = file.name() + ": dataset " + name;
  const h5::Handle dataset = h5::open_dataset(file, name);
  const std::vector<hsize_t> dims = h5::shape(dataset.get());
  if (dims.size() != 3) {
    throw Error(where + " has shape " + h5::shape_text(dims) +
                ", expected rank 3 in (z, y, x) order");
  }
  const h5::Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_INTEGER || H5Tget_size(type.get()) > 2 ||
      H5Tget_sign(type.get()) != H5T_SGN_NONE) {
    throw Error(where + " holds " + type_text(type.get()) +
                ", expected unsigned 8- or 16-bit integers (convert the data first)");
  }
  const int bits = H5Tget_size(type.get()) == 1 ? 8 : 16;

  const Box box = resolve_region(options.region, std::int64_t(dims[2]), std::int64_t(dims[1]),
                                 std::int64_t(dims[0]), where);
  Stack stack = allocate_stack(box, bits, where);
  // Only the box's hyperslab leaves the file; HDF5 widens 8-bit values to 16.
  const std::array<hsize_t, 3> start = {hsize_t(box.z0), hsize_t(box.y0), hsize_t(box.x0)};
  const std::array<hsize_t, 3> count = {hsize_t(box.nz), hsize_t(box.ny), hsize_t(box.nx)};
  const h5::Handle file_space(H5Dget_space(dataset.get()), H5Sclose);
  const h5::Handle memory_space(H5Screate_simple(3, count.data(), nullptr), H5Sclose);
  if (file_space.get() < 0 || memory_space.get() < 0 ||
      H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                          nullptr) < 0 ||
      H5Dread(dataset.get(), H5T_NATIVE_UINT16, memory_space.get(), file_space.get(), H5P_DEFAULT,
              stack.voxels.data()) < 0) {
    throw Error(where + ": cannot read its data (file truncated or damaged?)");
  }
  stack.voxel_size = element_size(dataset.get());
  if (stack.voxel_size) stack.unit = "um";
  return stack;
}

}  // namespace granmem::stack_io
