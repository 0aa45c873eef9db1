// Stacks from folders of slice images (PNG or TIFF, written by OpenCV) and from HDF5
// datasets; the voxel size given by the user; and the memory a read takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "granmem/core/error.hpp"
#include "granmem/tracking/stack.hpp"
#include "stack_formats.hpp"
#include "stack_samples.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
using namespace testing;  // the sample stacks and the writers of foreign files

// Slice z of `s` as an OpenCV image of its depth.
cv::Mat slice_image(const Stack& s, std::int64_t z) {
  cv::Mat image(int(s.ny), int(s.nx), s.bits == 8 ? CV_8UC1 : CV_16UC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      if (s.bits == 8) {
        image.at<std::uint8_t>(y, x) = std::uint8_t(s.at(x, y, z));
      } else {
        image.at<std::uint16_t>(y, x) = s.at(x, y, z);
      }
    }
  return image;
}

class SliceFolderTest : public testing::TempDirTest {
 protected:
  // The slices of `s` as <folder>/slice<z+1><extension>, written in a shuffled order so
  // that neither the file system's order nor the times give the stack order.
  fs::path write_slices(const Stack& s, const std::string& folder, const std::string& extension) {
    const fs::path dir = path(folder);
    fs::create_directories(dir);
    std::vector<std::int64_t> order(static_cast<std::size_t>(s.nz));
    for (std::size_t z = 0; z < order.size(); ++z)
      order[z] = std::int64_t(z);
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    for (const std::int64_t z : order) {
      const fs::path file = dir / ("slice" + std::to_string(z + 1) + extension);
      EXPECT_TRUE(cv::imwrite(file.string(), slice_image(s, z))) << file;
    }
    return dir;
  }
};

TEST_F(SliceFolderTest, SlicesAreReadInNaturalOrderBitForBit) {
  for (const char* extension : {".png", ".tif"}) {
    for (const int bits : {8, 16}) {
      // Twelve slices: slice2 must come before slice10 (which a plain sort puts second).
      const Stack truth = pattern_stack(21, 14, 12, bits);
      const std::string folder = std::string("f") + extension + std::to_string(bits);
      const fs::path dir = write_slices(truth, folder, extension);
      write_bytes(dir / "notes.txt", "not a slice");  // other files are passed over
      write_bytes(dir / ".slice0.png", "hidden");

      const Stack s = read_stack(dir);
      expect_same_voxels(s, truth);
      EXPECT_FALSE(s.voxel_size);
      EXPECT_EQ(s.source, dir.string());

      StackReadOptions options;
      options.region = inner_region(truth);
      expect_same_voxels(read_stack(dir, options), crop(truth, *options.region));
      options.region = Region{0, 0, 12, 0, 0, 0};
      expect_read_error(dir, {"region z [12, end) lies outside the stack"}, options);
    }
  }
}

TEST_F(SliceFolderTest, NaturalOrderComparesNumbersByValue) {
  std::vector<std::string> names = {"s10.png", "s2.png", "s1.png", "s02b.png",
                                    "s.png",   "t1.png", "s9.png", "s100.png"};
  std::sort(names.begin(), names.end(), natural_less);
  EXPECT_EQ(names, (std::vector<std::string>{"s.png", "s1.png", "s2.png", "s02b.png", "s9.png",
                                             "s10.png", "s100.png", "t1.png"}));
}

TEST_F(SliceFolderTest, ASinglePngIsAStackOfOneSlice) {
  const Stack truth = pattern_stack(9, 7, 1, 16);
  ASSERT_TRUE(cv::imwrite(path("one.png").string(), slice_image(truth, 0)));
  expect_same_voxels(read_stack(path("one.png")), truth);
}

TEST_F(SliceFolderTest, EmptyFoldersAndFoldersWithoutSlicesAreRefused) {
  fs::create_directories(path("empty"));
  expect_read_error(path("empty"), {"empty folder", "expected slice images"});
  fs::create_directories(path("texts"));
  write_bytes(path("texts") / "a.txt", "x");
  expect_read_error(path("texts"), {"none of its 1 files is a slice image"});
}

TEST_F(SliceFolderTest, SlicesOfUnequalSizeAreRefusedNamingTheSlice) {
  const fs::path dir = write_slices(pattern_stack(16, 12, 4, 8), "sizes", ".png");
  ASSERT_TRUE(
      cv::imwrite((dir / "slice3.png").string(), slice_image(pattern_stack(16, 13, 1, 8), 0)));
  expect_read_error(dir,
                    {"slice 3 of 4", "16x13 pixels of 8 bits, expected 16x12", "like slice1.png"},
                    {}, dir / "slice3.png");

  const fs::path depths = write_slices(pattern_stack(16, 12, 3, 8), "depths", ".tif");
  ASSERT_TRUE(
      cv::imwrite((depths / "slice2.tif").string(), slice_image(pattern_stack(16, 12, 1, 16), 0)));
  expect_read_error(depths, {"slice 2 of 3", "16x12 pixels of 16 bits, expected 16x12 pixels of 8"},
                    {}, depths / "slice2.tif");
}

TEST_F(SliceFolderTest, CorruptSlicesAreNamed) {
  const fs::path dir = write_slices(pattern_stack(16, 12, 3, 8), "png", ".png");
  const std::string bytes = file_bytes(dir / "slice2.png");
  write_bytes(dir / "slice2.png", bytes.substr(0, bytes.size() / 2));
  expect_read_error(dir, {"slice 2 of 3", "truncated"}, {}, dir / "slice2.png");
  // Damaged inside, whole at the end: OpenCV cannot decode it.
  std::string damaged = file_bytes(dir / "slice3.png");
  damaged.replace(8, 30, std::string(30, 'x'));
  write_bytes(dir / "slice3.png", damaged);
  write_bytes(dir / "slice2.png", bytes);
  expect_read_error(dir, {"slice 3 of 3", "cannot decode"}, {}, dir / "slice3.png");

  const fs::path tifs = write_slices(pattern_stack(16, 12, 3, 8), "tif", ".tif");
  write_bytes(tifs / "slice3.tif", std::string(100, 'x'));
  expect_read_error(tifs, {"cannot open as TIFF"}, {}, tifs / "slice3.tif");
}

// ---- HDF5 ---------------------------------------------------------------------------------

class Hdf5StackTest : public testing::TempDirTest {};

TEST_F(Hdf5StackTest, DatasetsInZyxOrderAreReadBitForBit) {
  for (const int bits : {8, 16}) {
    const Stack truth = pattern_stack(19, 13, 6, bits);
    const fs::path file = path("scan" + std::to_string(bits) + ".h5");
    write_hdf5_stack(file, "/scan/volume", truth);
    write_hdf5_stack(file, "/scan/other", pattern_stack(4, 4, 4, 8), false);

    StackReadOptions options;
    options.dataset = "/scan/volume";
    const Stack s = read_stack(file, options);
    expect_same_voxels(s, truth);
    EXPECT_FALSE(s.voxel_size);

    options.region = inner_region(truth);
    expect_same_voxels(read_stack(file, options), crop(truth, *options.region));
    options.region = Region{0, 0, 0, 20, 0, 0};
    expect_read_error(file, {"dataset /scan/volume", "region x [0, 20) lies outside"}, options);

    // Two 3-D datasets: the one to read must be named.
    expect_read_error(file, {"several 3-D datasets", "/scan/other", "/scan/volume"});
  }
}

// As h5py users write scans: chunked and compressed.
TEST_F(Hdf5StackTest, ChunkedCompressedDatasetsAreReadByRegion) {
  if (H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0) GTEST_SKIP() << "HDF5 lacks deflate";
  const Stack truth = pattern_stack(40, 30, 9, 16);
  const hid_t creation = H5Pcreate(H5P_DATASET_CREATE);
  const hsize_t chunk[3] = {4, 16, 16};
  H5Pset_chunk(creation, 3, chunk);
  H5Pset_deflate(creation, 4);
  write_hdf5(path("chunked.h5"), "/volume", {9, 30, 40}, H5T_STD_U16LE, truth.voxels, true,
             creation);
  H5Pclose(creation);
  expect_same_voxels(read_stack(path("chunked.h5")), truth);
  StackReadOptions options;
  options.region = inner_region(truth);
  expect_same_voxels(read_stack(path("chunked.h5"), options), crop(truth, *options.region));
}

TEST_F(Hdf5StackTest, TheOnlyCubeIsReadWithoutANameWithItsElementSize) {
  const Stack truth = pattern_stack(8, 9, 10, 16);
  write_hdf5_stack(path("one.h5"), "/data", truth);
  const hid_t file = H5Fopen(path("one.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t dataset = H5Dopen2(file, "/data", H5P_DEFAULT);
  const hsize_t three = 3;
  const hid_t space = H5Screate_simple(1, &three, nullptr);
  const hid_t attribute =
      H5Acreate2(dataset, "element_size_um", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  const double zyx[3] = {2.5, 0.75, 0.5};
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, zyx);
  H5Aclose(attribute);
  H5Sclose(space);
  H5Dclose(dataset);
  H5Fclose(file);

  const Stack s = read_stack(path("one.h5"));
  expect_same_voxels(s, truth);
  ASSERT_TRUE(s.voxel_size);
  EXPECT_EQ(*s.voxel_size, Eigen::Vector3d(0.5, 0.75, 2.5));
  EXPECT_EQ(s.unit, "um");
}

TEST_F(Hdf5StackTest, DatasetsOfTheWrongRankOrTypeAreRefused) {
  const fs::path file = path("bad.h5");
  write_hdf5(file, "/flat", {4, 5}, H5T_STD_U8LE, std::vector<std::uint16_t>(20));
  write_hdf5(file, "/movie", {2, 3, 4, 5}, H5T_STD_U16LE, std::vector<std::uint16_t>(120), false);
  write_hdf5(file, "/real", {2, 3, 4}, H5T_IEEE_F32LE, std::vector<std::uint16_t>(24), false);
  write_hdf5(file, "/wide", {2, 3, 4}, H5T_STD_U32LE, std::vector<std::uint16_t>(24), false);
  write_hdf5(file, "/nothing", {0, 3, 4}, H5T_STD_U8LE, std::vector<std::uint16_t>(1), false);
  const std::string before = file_bytes(file);
  StackReadOptions options;
  options.dataset = "/nothing";
  expect_read_error(file, {"dataset /nothing: an empty stack (4x3x0 voxels)"}, options);
  options.dataset = "/flat";
  expect_read_error(file, {"dataset /flat has shape [4,5], expected rank 3"}, options);
  options.dataset = "/movie";
  expect_read_error(file, {"dataset /movie has shape [2,3,4,5], expected rank 3"}, options);
  options.dataset = "/real";
  expect_read_error(file, {"32-bit floating-point", "expected unsigned 8- or 16-bit"}, options);
  options.dataset = "/wide";
  expect_read_error(file, {"unsigned 32-bit integers"}, options);
  options.dataset = "/missing";
  expect_read_error(file, {"missing dataset /missing"}, options);
  EXPECT_EQ(file_bytes(file), before);  // opened read-only, unchanged

  // A dataset named for a file that is no HDF5 file.
  write_tiff(pattern_stack(4, 4, 2, 8), path("s.tif"));
  options.dataset = "/volume";
  expect_read_error(path("s.tif"), {"not an HDF5 file", "'/volume'"}, options);
  expect_read_error(path("none.h5"), {"no such file"}, options);
}

TEST_F(Hdf5StackTest, ATruncatedFileIsReported) {
  write_hdf5_stack(path("whole.h5"), "/v", pattern_stack(64, 64, 16, 16));
  const std::string bytes = file_bytes(path("whole.h5"));
  write_bytes(path("cut.h5"), bytes.substr(0, bytes.size() / 2));
  StackReadOptions options;
  options.dataset = "/v";
  expect_read_error(path("cut.h5"), {}, options);
}

// ---- Voxel size given by the user ------------------------------------------------------

class StackVoxelSizeTest : public testing::TempDirTest {};

TEST_F(StackVoxelSizeTest, TheUserVoxelSizeReplacesTheFilesAndIsChecked) {
  const fs::path file = path("s.tif");
  Stack s = pattern_stack(8, 8, 2, 8);
  s.voxel_size = Eigen::Vector3d(1, 1, 1);
  s.unit = "um";
  write_tiff(s, file);
  StackReadOptions options;
  options.voxel_size = Eigen::Vector3d(0.05, 0.05, 0.075);
  options.unit = "mm";
  const Stack read = read_stack(file, options);
  EXPECT_EQ(*read.voxel_size, *options.voxel_size);
  EXPECT_EQ(read.unit, "mm");
  options.unit = "voxel";
  expect_read_error(file, {"voxel size", "expected three positive sizes in m, cm, mm or um"},
                    options);
  options.unit = "mm";
  options.voxel_size = Eigen::Vector3d(0.05, 0, 0.075);
  expect_read_error(file, {"voxel size"}, options);
}

// ---- Memory ------------------------------------------------------------------------------

// A field of /proc/self/status in KiB ("VmRSS", "VmHWM"), -1 where there is none.
long status_kib(const std::string& key) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1));
  }
  return -1;
}

// The rise of the peak resident memory while `read` runs, in bytes, measured from a heap
// handed back to the system first (freed memory reused would hide an allocation); -1
// where the system cannot reset the peak.
template <class F>
long peak_rise(F&& read) {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
  std::ofstream reset("/proc/self/clear_refs");
  reset << "5";  // resets VmHWM to the resident size now
  reset.close();
  if (!reset) return -1;
  const long before = status_kib("VmRSS");
  if (before < 0) return -1;
  read();
  return (status_kib("VmHWM") - before) * 1024;
}

class StackMemoryTest : public testing::TempDirTest {};

// A read holds the 16-bit stack and little more: a strip, a slice or HDF5's own buffers,
// never the whole file (for an 8-bit source the stack itself is twice the file).
TEST_F(StackMemoryTest, ReadingHoldsTheStackAndLittleMore) {
  const std::int64_t nx = 1024, ny = 1024, nz = 24;
  const long stack_bytes = long(2 * nx * ny * nz);  // 48 MiB
  const long slack = 6 << 20;
  Stack truth(nx, ny, 1, 8);
  for (auto& v : truth.voxels)
    v = std::uint16_t(&v - truth.voxels.data()) & 0xff;

  // 24 MiB of 8-bit TIFF and HDF5 written slice by slice: the test holds one slice.
  testing::TiffLayout strips;
  strips.rows_per_strip = 64;
  TIFF* tif = testing::open_tiff_for_writing(path("big.tif"), strips);
  for (std::int64_t z = 0; z < nz; ++z)
    testing::write_tiff_page(tif, truth, 0, strips);
  TIFFClose(tif);
  write_hdf5(path("big.h5"), "/v", {hsize_t(nz), hsize_t(ny), hsize_t(nx)}, H5T_STD_U8LE,
             std::vector<std::uint16_t>(std::size_t(nx * ny * nz), 7));

  for (const char* name : {"big.tif", "big.h5"}) {
    Stack s;
    const long rise = peak_rise([&] { s = read_stack(path(name)); });
    if (rise < 0) GTEST_SKIP() << "no /proc/self/clear_refs to measure with";
    EXPECT_EQ(s.nz, nz);
    EXPECT_LE(rise, stack_bytes + slack) << name << ": the stack is " << stack_bytes << " bytes";
    EXPECT_GE(rise, stack_bytes / 2) << name << ": the measurement saw no stack";
  }
}

}  // namespace
}  // namespace granmem
