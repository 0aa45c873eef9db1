// Multi-page TIFF stacks: foreign files written by libtiff (strips, tiles, compressed,
// BigTIFF, big-endian), our writer's round trip with its ImageJ metadata, OME-XML, and
// each kind of bad file.
#include <gtest/gtest.h>

#include <array>

#include <tuple>

#include "granmem/core/error.hpp"
#include "granmem/tracking/stack.hpp"
#include "stack_formats.hpp"
#include "stack_samples.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
using namespace testing;  // the sample stacks and the writers of foreign files

class TiffStackTest : public testing::TempDirTest {};

// ---- Foreign files: every layout libtiff writes, whole and cropped ----------------------

// bits, tiled, compression, BigTIFF
using TiffCase = std::tuple<int, bool, std::uint16_t, bool>;

class ForeignTiffTest : public testing::TempDirTest,
                        public ::testing::WithParamInterface<TiffCase> {};

TEST_P(ForeignTiffTest, ReadsTheVoxelsBitForBitWholeAndCropped) {
  const auto [bits, tiled, compression, big] = GetParam();
  if (!TIFFIsCODECConfigured(compression)) GTEST_SKIP() << "libtiff lacks the codec";
  // Sizes that are no multiple of the tiles (16) or strips (4): partial blocks at the edges.
  const Stack truth = pattern_stack(37, 29, 5, bits);
  TiffLayout layout;
  layout.tile = tiled ? 16 : 0;
  layout.rows_per_strip = 4;
  layout.compression = compression;
  layout.big = big;
  const fs::path file = path("stack.tif");
  write_libtiff(file, truth, layout);
  ASSERT_EQ(file_bytes(file).substr(0, 4), std::string(big ? "II+\0" : "II*\0", 4));

  const Stack whole = read_stack(file);
  expect_same_voxels(whole, truth);
  EXPECT_FALSE(whole.voxel_size);  // no metadata: in voxels
  EXPECT_EQ(whole.source, file.string());

  const Region r = inner_region(truth);  // crosses tile and strip edges
  StackReadOptions options;
  options.region = r;
  expect_same_voxels(read_stack(file, options), crop(truth, r));

  options.region = Region{30, 0, 4, 0, 0, 0};  // to the end along every axis
  expect_same_voxels(read_stack(file, options), crop(truth, Region{30, 0, 4, 7, 29, 1}));
}

std::string tiff_case_name(const ::testing::TestParamInfo<TiffCase>& info) {
  const auto [bits, tiled, compression, big] = info.param;
  const char* codec = compression == COMPRESSION_NONE  ? "Raw"
                      : compression == COMPRESSION_LZW ? "Lzw"
                                                       : "Deflate";
  return std::to_string(bits) + "Bit" + (tiled ? "Tiles" : "Strips") + codec +
         (big ? "BigTiff" : "Classic");
}

INSTANTIATE_TEST_SUITE_P(Layouts, ForeignTiffTest,
                         ::testing::Combine(::testing::Values(8, 16), ::testing::Bool(),
                                            ::testing::Values(COMPRESSION_NONE, COMPRESSION_LZW,
                                                              COMPRESSION_ADOBE_DEFLATE),
                                            ::testing::Bool()),
                         tiff_case_name);

TEST_F(TiffStackTest, BigEndianSixteenBitFilesKeepTheirValues) {
  const Stack truth = pattern_stack(20, 13, 3, 16);
  TiffLayout layout;
  layout.big_endian = true;
  write_libtiff(path("mm.tif"), truth, layout);
  ASSERT_EQ(file_bytes(path("mm.tif")).substr(0, 2), "MM");
  expect_same_voxels(read_stack(path("mm.tif")), truth);
}

TEST_F(TiffStackTest, MinIsWhitePagesAreInvertedSoThatZeroIsBlack) {
  for (const int bits : {8, 16}) {
    const Stack truth = pattern_stack(16, 12, 2, bits);
    TiffLayout layout;
    layout.min_is_white = true;  // stores max - value
    write_libtiff(path("white.tif"), truth, layout);
    expect_same_voxels(read_stack(path("white.tif")), truth);
  }
}

TEST_F(TiffStackTest, OnePageIsAStackOfOneSlice) {
  const Stack truth = pattern_stack(16, 12, 1, 8);
  write_libtiff(path("one.tif"), truth);
  expect_same_voxels(read_stack(path("one.tif")), truth);
}

// ---- Our writer: round trip, layout, metadata -------------------------------------------

TEST_F(TiffStackTest, WriteTiffRoundTripsVoxelsAndImageJVoxelSize) {
  for (const int bits : {8, 16}) {
    Stack s = pattern_stack(33, 21, 4, bits);
    s.voxel_size = Eigen::Vector3d(0.05, 0.0625, 0.075);
    s.unit = "mm";
    write_tiff(s, path("ours.tif"));
    EXPECT_EQ(file_bytes(path("ours.tif")).substr(0, 4), std::string("II*\0", 4));

    const Stack back = read_stack(path("ours.tif"));
    expect_same_voxels(back, s);
    ASSERT_TRUE(back.voxel_size);
    EXPECT_EQ(*back.voxel_size, *s.voxel_size);  // the same doubles, not nearly
    EXPECT_EQ(back.unit, "mm");

    StackReadOptions options;
    options.region = inner_region(s);
    const Stack part = read_stack(path("ours.tif"), options);
    expect_same_voxels(part, crop(s, *options.region));
    EXPECT_EQ(*part.voxel_size, *s.voxel_size);
  }
}

TEST_F(TiffStackTest, EachUnitSurvivesTheRoundTrip) {
  const std::tuple<const char*, Eigen::Vector3d> cases[] = {
      {"um", {0.4, 0.4, 1.2}},     // written as ImageJ's "micron"
      {"cm", {0.01, 0.02, 0.03}},  // also as the TIFF resolution unit
      {"m", {2e-5, 2e-5, 3e-5}},
  };
  for (const auto& [unit, size] : cases) {
    Stack s = pattern_stack(12, 12, 2, 8);
    s.voxel_size = size;
    s.unit = unit;
    write_tiff(s, path("unit.tif"));
    const Stack back = read_stack(path("unit.tif"));
    ASSERT_TRUE(back.voxel_size) << unit;
    EXPECT_EQ(*back.voxel_size, size) << unit;
    EXPECT_EQ(back.unit, unit);
  }
  // Without a voxel size, the file says none and the stack stays in voxels.
  write_tiff(pattern_stack(12, 12, 2, 8), path("plain.tif"));
  EXPECT_FALSE(read_stack(path("plain.tif")).voxel_size);
}

TEST_F(TiffStackTest, ForcedBigTiffRoundTrips) {
  Stack s = pattern_stack(19, 17, 3, 16);
  s.voxel_size = Eigen::Vector3d(1.5, 1.5, 4);
  s.unit = "um";
  stack_io::write_tiff_stack(s, path("big.tif"), stack_io::TiffFormat::big);
  EXPECT_EQ(file_bytes(path("big.tif")).substr(0, 4), std::string("II+\0", 4));
  const Stack back = read_stack(path("big.tif"));
  expect_same_voxels(back, s);
  EXPECT_EQ(*back.voxel_size, *s.voxel_size);
  EXPECT_EQ(back.unit, "um");
}

// The classic file's first directory, at offset 8 of a little-endian file: where its
// entry for `tag` and its next-directory offset lie.
std::size_t first_directory_entry(const std::string& bytes, std::uint16_t tag) {
  const auto u16 = [&](std::size_t at) {
    return std::uint16_t(std::uint8_t(bytes[at]) | std::uint8_t(bytes[at + 1]) << 8);
  };
  const std::size_t count = u16(8);
  for (std::size_t e = 0; e < count; ++e) {
    if (u16(10 + 12 * e) == tag) return 10 + 12 * e;
  }
  return 10 + 12 * count;  // no such tag: the next-directory offset
}

// ImageJ reads a stack as images stored one after the other behind the first page's data
// and ignores the other directories, as it writes stacks over 4 GB. Our writer must lay
// the data out so; cutting the directory chain after the first page shows whether it did,
// and exercises the reader of such files.
TEST_F(TiffStackTest, WrittenDataAreContiguousAsImageJReadsThem) {
  for (const int bits : {8, 16}) {
    Stack s = pattern_stack(bits == 8 ? 512 : 256, 300, 5, bits);  // two strips a page
    s.voxel_size = Eigen::Vector3d(0.5, 0.5, 2);
    s.unit = "um";
    write_tiff(s, path("ij.tif"));
    std::string bytes = file_bytes(path("ij.tif"));
    const std::size_t next = first_directory_entry(bytes, 0xFFFF);
    bytes.replace(next, 4, std::string(4, '\0'));
    write_bytes(path("single_directory.tif"), bytes);

    const Stack back = read_stack(path("single_directory.tif"));
    expect_same_voxels(back, s);
    EXPECT_EQ(*back.voxel_size, *s.voxel_size);
    StackReadOptions options;
    options.region = inner_region(s);
    expect_same_voxels(read_stack(path("single_directory.tif"), options), crop(s, *options.region));

    // Cut within the images: the message says how many are there.
    write_bytes(path("cut.tif"), bytes.substr(0, bytes.size() / 2));
    expect_read_error(path("cut.tif"), {"ImageJ stack of 5 images", "expected 5", "truncated"});
  }
}

TEST_F(TiffStackTest, ForeignImageJMetadataGivesTheVoxelSize) {
  const Stack truth = pattern_stack(16, 16, 4, 16);
  TiffLayout layout;
  layout.description = "ImageJ=1.54f\nimages=4\nslices=4\nunit=\\u00B5m\nspacing=2.5\nloop=false\n";
  layout.x_resolution = 2;  // pixels per micrometre
  layout.y_resolution = 4;
  write_libtiff(path("ij.tif"), truth, layout);
  const Stack s = read_stack(path("ij.tif"));
  expect_same_voxels(s, truth);
  ASSERT_TRUE(s.voxel_size);
  EXPECT_EQ(*s.voxel_size, Eigen::Vector3d(0.5, 0.25, 2.5));
  EXPECT_EQ(s.unit, "um");

  // No unit in the description: the TIFF resolution unit (centimetres), z of 1 unit.
  layout.description = "ImageJ=1.54f\nimages=4\nslices=4\n";
  layout.x_resolution = layout.y_resolution = 100;
  layout.resolution_unit = RESUNIT_CENTIMETER;
  write_libtiff(path("cm.tif"), truth, layout);
  const Stack cm = read_stack(path("cm.tif"));
  EXPECT_EQ(*cm.voxel_size, Eigen::Vector3d(0.01, 0.01, 1));
  EXPECT_EQ(cm.unit, "cm");

  // "pixel": no length, no voxel size.
  layout.description = "ImageJ=1.54f\nimages=4\nslices=4\nunit=pixel\n";
  layout.resolution_unit = RESUNIT_NONE;
  write_libtiff(path("px.tif"), truth, layout);
  EXPECT_FALSE(read_stack(path("px.tif")).voxel_size);
}

TEST_F(TiffStackTest, OmeXmlGivesTheVoxelSizeInTheUnitOfX) {
  const Stack truth = pattern_stack(16, 16, 3, 8);
  TiffLayout layout;
  layout.description =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>"
      "<OME xmlns=\"http://www.openmicroscopy.org/Schemas/OME/2016-06\">"
      "<Image ID=\"Image:0\"><Pixels ID=\"Pixels:0\" DimensionOrder=\"XYZCT\" Type=\"uint8\" "
      "SizeX=\"16\" SizeY=\"16\" SizeZ=\"3\" SizeC=\"1\" SizeT=\"1\" PhysicalSizeX=\"0.4\" "
      "PhysicalSizeXUnit=\"&#181;m\" PhysicalSizeY=\"0.4\" PhysicalSizeZ=\"1.2\" "
      "PhysicalSizeZUnit=\"mm\"><TiffData/></Pixels></Image></OME>";
  write_libtiff(path("ome.tif"), truth, layout);
  const Stack s = read_stack(path("ome.tif"));
  expect_same_voxels(s, truth);
  ASSERT_TRUE(s.voxel_size);
  EXPECT_EQ(s.unit, "um");
  EXPECT_EQ(s.voxel_size->x(), 0.4);
  EXPECT_EQ(s.voxel_size->y(), 0.4);  // no unit: micrometres, the schema's default
  EXPECT_DOUBLE_EQ(s.voxel_size->z(), 1200);

  // A namespace prefix, every axis in millimetres.
  layout.description =
      "<ome:OME xmlns:ome=\"http://www.openmicroscopy.org/Schemas/OME/2016-06\"><ome:Image>"
      "<ome:Pixels SizeZ='3' PhysicalSizeX='0.05' PhysicalSizeXUnit='mm' PhysicalSizeY='0.05' "
      "PhysicalSizeYUnit='mm' PhysicalSizeZ='0.075' PhysicalSizeZUnit='mm'/></ome:Image>"
      "</ome:OME>";
  write_libtiff(path("prefixed.tif"), truth, layout);
  const Stack p = read_stack(path("prefixed.tif"));
  EXPECT_EQ(*p.voxel_size, Eigen::Vector3d(0.05, 0.05, 0.075));
  EXPECT_EQ(p.unit, "mm");
}

TEST_F(TiffStackTest, HyperstacksOfSeveralChannelsAreRefused) {
  TiffLayout layout;
  layout.description = "ImageJ=1.54f\nimages=4\nchannels=2\nslices=2\nhyperstack=true\n";
  write_libtiff(path("hyper.tif"), pattern_stack(16, 16, 4, 8), layout);
  expect_read_error(path("hyper.tif"), {"2 channels", "expected one channel"});
}

// Counts beyond any stack (found by fuzz_tiff: 2e30 slices overflowed the integer they were
// cast to) are one clear error, in ImageJ's description and in OME's XML alike.
TEST_F(TiffStackTest, CountsBeyondAnyStackAreRefused) {
  TiffLayout imagej;
  imagej.description = "ImageJ=0.11a\nslices=2" + std::string(30, '2') + "\n";
  write_libtiff(path("imagej.tif"), pattern_stack(16, 16, 4, 8), imagej);
  expect_read_error(path("imagej.tif"), {"imagej.tif", "ImageJ metadata", "slices=", "beyond"});
  TiffLayout ome;
  ome.description =
      "<?xml version='1.0'?><OME><Image><Pixels SizeZ='1e300' PhysicalSizeX='0.05'/>"
      "</Image></OME>";
  write_libtiff(path("ome.tif"), pattern_stack(16, 16, 4, 8), ome);
  expect_read_error(path("ome.tif"), {"ome.tif", "OME metadata", "SizeZ=1e300", "beyond"});
}

// A tile far beyond its page (fuzz_tiff's input: tiles of 268 million rows on a 13-row
// page) is refused before its buffer is allocated; one that merely overhangs is read.
TEST_F(TiffStackTest, TilesFarLargerThanTheirPageAreRefused) {
  TiffLayout huge;
  huge.tile = 4096;  // 32 MiB of 16-bit pixels for a 20 x 12 page
  huge.compression = COMPRESSION_LZW;
  write_libtiff(path("huge.tif"), pattern_stack(20, 12, 2, 16), huge);
  expect_read_error(path("huge.tif"), {"huge.tif", "4096 x 4096", "20 x 12", "tile layout"});
  TiffLayout overhang;
  overhang.tile = 256;
  const Stack truth = pattern_stack(20, 12, 2, 16);
  write_libtiff(path("overhang.tif"), truth, overhang);
  expect_same_voxels(read_stack(path("overhang.tif")), truth);
}

// ---- Bad input: one line naming the file, nothing written ------------------------------

TEST_F(TiffStackTest, TruncatedFilesAreReportedNotMisread) {
  // libtiff's layout (each page's data, then its directory) and ours (all data, then the
  // directories), both cut in half.
  const Stack truth = pattern_stack(40, 30, 6, 16);
  write_libtiff(path("libtiff.tif"), truth);
  write_tiff(truth, path("ours.tif"));
  TiffLayout lzw;
  lzw.compression = COMPRESSION_LZW;
  write_libtiff(path("lzw.tif"), truth, lzw);
  for (const char* name : {"libtiff.tif", "ours.tif", "lzw.tif"}) {
    const std::string whole = file_bytes(path(name));
    const fs::path cut = path(std::string("cut_") + name);
    write_bytes(cut, whole.substr(0, whole.size() / 2));
    expect_read_error(cut, {"truncated"});
    EXPECT_EQ(file_bytes(cut).size(), whole.size() / 2);  // read, never written
  }
  // Cut within the data of a file whose directory is intact: our one-page file holds its
  // directory in front of the data.
  write_tiff(pattern_stack(40, 30, 1, 8), path("one_page.tif"));
  const std::string bytes = file_bytes(path("one_page.tif"));
  write_bytes(path("short_data.tif"), bytes.substr(0, bytes.size() - 100));
  expect_read_error(path("short_data.tif"), {"page 1 of 1", "cannot read strip 0"});
}

TEST_F(TiffStackTest, GarbageIsNotATiff) {
  write_bytes(path("garbage.tif"), std::string(1000, '\x5a'));
  expect_read_error(path("garbage.tif"), {"not a TIFF, PNG or HDF5 file"});
  // A TIFF signature in front of garbage.
  write_bytes(path("posing.tif"), std::string("II*\0", 4) + std::string(1000, '\xff'));
  expect_read_error(path("posing.tif"), {"TIFF"});
  write_bytes(path("empty.tif"), "");
  expect_read_error(path("empty.tif"), {"empty file"});
  expect_read_error(path("missing.tif"), {"no such file"});
}

// A 138-byte file whose one page declares 100000 x 100000 16-bit pixels (20 GB): refused
// from its length before anything is allocated (it used to take 11 GB and run on).
TEST_F(TiffStackTest, AbsurdDeclaredSizesAreRefusedBeforeAllocating) {
  auto u16 = [](std::uint32_t v) { return std::string{char(v & 0xff), char(v >> 8)}; };
  auto u32 = [&](std::uint32_t v) { return u16(v & 0xffff) + u16(v >> 16); };
  const std::uint32_t side = 100000;
  const std::vector<std::array<std::uint32_t, 3>> tags{
      {256, 4, side}, {257, 4, side}, {258, 3, 16},   {259, 3, 1},          {262, 3, 1},
      {273, 4, 8},    {277, 3, 1},    {278, 4, side}, {279, 4, 4000000000u}};
  std::string bytes = std::string("II*\0", 4) + u32(24) + std::string(16, '\0') + u16(9);
  for (const auto& [tag, type, value] : tags)
    bytes += u16(tag) + u16(type) + u32(1) + (type == 3 ? u16(value) + u16(0) : u32(value));
  bytes += u32(0);
  write_bytes(path("huge.tif"), bytes);
  expect_read_error(path("huge.tif"),
                    {"1 page of 100000x100000 pixels", "more than any compression", "138 bytes"});
}

TEST_F(TiffStackTest, PagesOfUnequalSizeAreRefused) {
  write_libtiff_pages(path("mixed.tif"), {pattern_stack(16, 12, 1, 8), pattern_stack(16, 12, 1, 8),
                                          pattern_stack(18, 12, 1, 8)});
  expect_read_error(path("mixed.tif"), {"page 3 of 3", "18x12", "expected 16x12"});
  write_libtiff_pages(path("depths.tif"),
                      {pattern_stack(16, 12, 1, 8), pattern_stack(16, 12, 1, 16)});
  expect_read_error(path("depths.tif"), {"page 2 of 2", "16-bit, expected 8-bit"});
}

TEST_F(TiffStackTest, UnsupportedSamplesAndCodecsAreRefused) {
  // RGB.
  TIFF* tif = TIFFOpen(path("rgb.tif").c_str(), "w");
  const unsigned char rgb[3 * 4] = {};
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, 4u);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, 1u);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 8);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 3);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFWriteScanline(tif, const_cast<unsigned char*>(rgb), 0, 0);
  TIFFClose(tif);
  expect_read_error(path("rgb.tif"), {"3 samples per pixel", "expected a grayscale image"});

  // A compression scheme libtiff has no codec for (JPEG 2000's code), patched into a
  // file of ours.
  write_tiff(pattern_stack(16, 12, 2, 8), path("codec.tif"));
  std::string bytes = file_bytes(path("codec.tif"));
  const std::size_t entry = first_directory_entry(bytes, TIFFTAG_COMPRESSION);
  bytes[entry + 8] = char(34712 & 0xff);
  bytes[entry + 9] = char(34712 >> 8);
  write_bytes(path("codec.tif"), bytes);
  expect_read_error(path("codec.tif"), {"page 1 of 2", "compression scheme 34712"});
}

TEST_F(TiffStackTest, RegionOutsideTheStackIsAnError) {
  write_tiff(pattern_stack(20, 10, 4, 8), path("s.tif"));
  StackReadOptions options;
  options.region = Region{0, 0, 3, 0, 0, 2};
  expect_read_error(path("s.tif"), {"region z [3, 5) lies outside the stack", "z [0, 4)"}, options);
  options.region = Region{20, 0, 0, 0, 0, 0};
  expect_read_error(path("s.tif"), {"region x [20, end)"}, options);
  options.region = Region{-1, 0, 0, 5, 0, 0};
  expect_read_error(path("s.tif"), {"region x [-1, 4)"}, options);
  options.region = Region{0, 2, 0, 0, 9, 0};
  expect_read_error(path("s.tif"), {"region y [2, 11)", "20x10x4 voxels"}, options);
}

TEST_F(TiffStackTest, AFailedWriteLeavesTheOldFileAlone) {
  write_tiff(pattern_stack(12, 12, 2, 8), path("keep.tif"));
  const std::string before = file_bytes(path("keep.tif"));
  Stack bad = pattern_stack(12, 12, 2, 8);
  bad.at(3, 4, 1) = 300;  // more than 8 bits hold
  const std::string message = testing::error_message([&] { write_tiff(bad, path("keep.tif")); });
  EXPECT_NE(message.find("voxel (3, 4, 1) is 300"), std::string::npos) << message;
  Stack unitless = pattern_stack(12, 12, 2, 8);
  unitless.voxel_size = Eigen::Vector3d(1, 1, 1);
  unitless.unit = "voxel";
  EXPECT_NE(testing::error_message([&] { write_tiff(unitless, path("keep.tif")); }).find("voxel"),
            std::string::npos);
  EXPECT_EQ(file_bytes(path("keep.tif")), before);
  EXPECT_EQ(listing(), std::vector<std::string>{"keep.tif"});  // no temporary file left
}

}  // namespace
}  // namespace granmem
