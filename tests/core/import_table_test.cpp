#include "granmem/core/import_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class ImportTable : public granmem::testing::TempDirTest {
 protected:
  // Writes `csv` to a file and returns the message of the Error import_table throws.
  std::string import_error(const std::string& csv, const ImportOptions& options = {}) {
    const auto file = path("bad.csv");
    write_text(file, csv);
    try {
      import_table(file, options);
    } catch (const Error& e) {
      const std::string msg = e.what();
      return msg;
    }
    ADD_FAILURE() << "expected granmem::Error for:\n" << csv;
    return "";
  }

  // Expects that importing `csv` fails with a message holding the file name and `part`.
  void expect_error(const std::string& csv, const std::string& part,
                    const ImportOptions& options = {}) {
    const std::string msg = import_error(csv, options);
    EXPECT_NE(msg.find(path("bad.csv").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
  }
};

void expect_row(const Vectors3& m, Eigen::Index row, double x, double y, double z) {
  EXPECT_EQ(m(row, 0), x) << "row " << row;
  EXPECT_EQ(m(row, 1), y) << "row " << row;
  EXPECT_EQ(m(row, 2), z) << "row " << row;
}

void expect_nan_row(const Vectors3& m, Eigen::Index row) {
  for (int k = 0; k < 3; ++k)
    EXPECT_TRUE(std::isnan(m(row, k))) << "row " << row << " component " << k;
}

TEST_F(ImportTable, PandasTableInAnyColumnOrder) {
  const auto file = path("tracks.csv");
  write_text(file,
             "# exported from trackpy\n"
             ",z,particle,y,frame,x,size\n"
             "0,3.0,7,2.0,5,1.0,big\n"
             "1,6.0,2,5.0,5,4.0,small\n"
             "2,3.5,7,2.5,9,1.5,big\n");
  ImportSummary summary;
  const Trajectories run = import_table(file, {}, &summary);
  const RunHeader& h = run.header;
  EXPECT_EQ(h.id, (std::vector<std::int64_t>{2, 7}));  // particle labels, sorted
  EXPECT_EQ(h.length_unit, "voxel");
  EXPECT_EQ(h.time_unit, "cycle");
  EXPECT_EQ(h.sample, kSampleEndOfCycle);
  EXPECT_FALSE(h.has_axis);
  EXPECT_FALSE(h.has_orientation);
  EXPECT_FALSE(h.has_hole_contact);
  EXPECT_FALSE(h.box.has_value());
  EXPECT_FALSE(h.voxel_size.has_value());
  ASSERT_EQ(h.radius.size(), 2u);
  EXPECT_TRUE(std::isnan(h.radius[0]) && std::isnan(h.radius[1]));
  ASSERT_EQ(run.frames.size(), 2u);
  EXPECT_EQ(run.frames[0].step, 5);  // frame labels
  EXPECT_EQ(run.frames[1].step, 9);
  EXPECT_EQ(run.frames[0].time, 5.0);
  EXPECT_EQ(run.frames[1].time, 9.0);
  ASSERT_EQ(run.frames[0].position.rows(), 2);
  expect_row(run.frames[0].position, 0, 4.0, 5.0, 6.0);  // particle 2
  expect_row(run.frames[0].position, 1, 1.0, 2.0, 3.0);  // particle 7
  expect_nan_row(run.frames[1].position, 0);             // particle 2 not in frame 9
  expect_row(run.frames[1].position, 1, 1.5, 2.5, 3.5);
  EXPECT_EQ(run.frames[0].axis.rows(), 0);
  EXPECT_TRUE(run.frames[0].hole_contact.empty());
  EXPECT_TRUE(run.observables.empty());

  EXPECT_EQ(summary.rows, 3u);
  EXPECT_EQ(summary.frames, 2u);
  EXPECT_EQ(summary.grains, 2u);
  EXPECT_EQ(summary.missing, 1u);
  EXPECT_EQ(summary.axes_known, 0u);
  EXPECT_EQ(summary.length_unit, "voxel");
}

TEST_F(ImportTable, RowsInAnyOrderAndNegativeLabels) {
  const auto file = path("tracks.csv");
  write_text(file,
             "frame,particle,x,y,z\n"
             "3,-4,1,1,1\n"
             "-2,10,2,2,2\n"
             "3,10,3,3,3\n"
             "0,-4,4,4,4\n");
  ImportOptions options;
  options.length_unit = "um";
  const Trajectories run = import_table(file, options);
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{-4, 10}));
  EXPECT_EQ(run.header.length_unit, "um");
  ASSERT_EQ(run.frames.size(), 3u);
  EXPECT_EQ(run.frames[0].step, -2);
  EXPECT_EQ(run.frames[1].step, 0);
  EXPECT_EQ(run.frames[2].step, 3);
  expect_nan_row(run.frames[0].position, 0);
  expect_row(run.frames[0].position, 1, 2, 2, 2);
  expect_row(run.frames[1].position, 0, 4, 4, 4);
  expect_nan_row(run.frames[1].position, 1);
  expect_row(run.frames[2].position, 0, 1, 1, 1);
  expect_row(run.frames[2].position, 1, 3, 3, 3);
}

TEST_F(ImportTable, AnisotropicVoxelsScalePositionsAxesAndRadius) {
  const auto file = path("voxels.csv");
  write_text(file,
             "frame,particle,x,y,z,ax,ay,az,radius,hole_contact\n"
             "0,1,2,4,1,2,4,0.5,2,1\n"
             "0,2,10,20,30,0,0,-3,,0\n"
             "1,1,4,8,2,,,,4,0\n"
             "1,2,12,24,36,4,0,1,6,1\n");
  ImportOptions options;
  options.voxel_size = Eigen::Vector3d(0.5, 0.25, 2.0);
  options.voxel_size_unit = "mm";
  options.box = Box{Eigen::Vector3d(2, 4, 1), Eigen::Vector3d(10, 20, 30)};
  options.sample = kSampleInCycle;
  ImportSummary summary;
  const Trajectories run = import_table(file, options, &summary);
  const RunHeader& h = run.header;
  EXPECT_EQ(h.length_unit, "mm");
  EXPECT_EQ(h.sample, kSampleInCycle);
  ASSERT_TRUE(h.voxel_size.has_value());
  EXPECT_EQ(*h.voxel_size, Eigen::Vector3d(0.5, 0.25, 2.0));
  ASSERT_TRUE(h.box.has_value());
  EXPECT_EQ(h.box->lower, Eigen::Vector3d(1, 1, 2));
  EXPECT_EQ(h.box->edges, Eigen::Vector3d(5, 5, 60));
  EXPECT_TRUE(h.has_axis);
  EXPECT_TRUE(h.has_hole_contact);
  EXPECT_EQ(h.id, (std::vector<std::int64_t>{1, 2}));
  // Radius: mean over the frames that measured it, times the x voxel size.
  ASSERT_EQ(h.radius.size(), 2u);
  EXPECT_EQ(h.radius[0], 1.5);  // (2 + 4) / 2 * 0.5
  EXPECT_EQ(h.radius[1], 3.0);  // 6 * 0.5 (the empty field is not averaged in)

  ASSERT_EQ(run.frames.size(), 2u);
  const Frame& f0 = run.frames[0];
  const Frame& f1 = run.frames[1];
  expect_row(f0.position, 0, 1, 1, 2);
  expect_row(f0.position, 1, 5, 5, 60);
  expect_row(f1.position, 0, 2, 2, 4);
  expect_row(f1.position, 1, 6, 6, 72);
  // (2,4,0.5) voxels -> (1,1,1) mm, so the direction is (1,1,1)/sqrt(3), not (2,4,0.5)/|..|.
  const double s3 = 1 / std::sqrt(3.0), s2 = 1 / std::sqrt(2.0);
  EXPECT_DOUBLE_EQ(f0.axis(0, 0), s3);
  EXPECT_DOUBLE_EQ(f0.axis(0, 1), s3);
  EXPECT_DOUBLE_EQ(f0.axis(0, 2), s3);
  expect_row(f0.axis, 1, 0, 0, -1);
  expect_nan_row(f1.axis, 0);  // empty ax,ay,az: axis not seen
  // (4,0,1) voxels -> (2,0,2) mm.
  EXPECT_DOUBLE_EQ(f1.axis(1, 0), s2);
  EXPECT_EQ(f1.axis(1, 1), 0.0);
  EXPECT_DOUBLE_EQ(f1.axis(1, 2), s2);
  EXPECT_EQ(f0.hole_contact, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(f1.hole_contact, (std::vector<std::uint8_t>{0, 1}));

  EXPECT_EQ(summary.rows, 4u);
  EXPECT_EQ(summary.missing, 0u);
  EXPECT_EQ(summary.axes_known, 3u);
  EXPECT_EQ(summary.length_unit, "mm");
}

TEST_F(ImportTable, StandardErrorsAreScaledAsThePositionsAndKeptUnknownWhereEmpty) {
  // trackpy's one `ep`, in voxels of 0.5, 0.25, 2 mm: each axis' error scaled as its
  // coordinate; the axis' error (rad) kept as given.
  const auto file = path("errors.csv");
  write_text(file,
             "frame,particle,x,y,z,ep,axis_error\n"
             "0,1,2,4,1,0.1,0.01\n"
             "0,2,10,20,30,,\n");
  ImportOptions options;
  options.voxel_size = Eigen::Vector3d(0.5, 0.25, 2.0);
  options.voxel_size_unit = "mm";
  const Trajectories run = import_table(file, options);
  ASSERT_TRUE(run.header.has_position_error);
  ASSERT_TRUE(run.header.has_axis_error);
  const Frame& f = run.frames[0];
  EXPECT_DOUBLE_EQ(f.position_error(0, 0), 0.05);
  EXPECT_DOUBLE_EQ(f.position_error(0, 1), 0.025);
  EXPECT_DOUBLE_EQ(f.position_error(0, 2), 0.2);
  EXPECT_TRUE(f.position_error.row(1).array().isNaN().all());
  EXPECT_EQ(f.axis_error[0], 0.01);
  EXPECT_TRUE(std::isnan(f.axis_error[1]));

  // Per axis, in lengths.
  write_text(file, "frame,particle,x,y,z,ep_x,ep_y,ep_z\n0,1,2,4,1,0.1,0.2,0.3\n");
  ImportOptions in_mm;
  in_mm.length_unit = "mm";
  const Trajectories per_axis = import_table(file, in_mm);
  EXPECT_FALSE(per_axis.header.has_axis_error);
  expect_row(per_axis.frames[0].position_error, 0, 0.1, 0.2, 0.3);
}

TEST_F(ImportTable, RadiusOptionIsTheFallbackForTablesWithoutRadius) {
  const auto file = path("tracks.csv");
  write_text(file, "frame,particle,x,y,z\n0,1,1,2,3\n0,2,4,5,6\n");
  ImportOptions options;
  options.radius = 2.0;
  options.length_unit = "cm";
  Trajectories run = import_table(file, options);
  EXPECT_EQ(run.header.length_unit, "cm");
  EXPECT_EQ(run.header.radius, (std::vector<double>{2.0, 2.0}));

  options = {};
  options.radius = 3.0;
  options.voxel_size = Eigen::Vector3d(0.25, 1, 1);
  options.voxel_size_unit = "um";
  run = import_table(file, options);
  EXPECT_EQ(run.header.length_unit, "um");
  EXPECT_EQ(run.header.radius, (std::vector<double>{0.75, 0.75}));
  expect_row(run.frames[0].position, 1, 1, 5, 6);

  // A grain whose radius column is empty in every frame falls back on nothing: NaN.
  write_text(file, "frame,particle,x,y,z,radius\n0,1,1,2,3,\n0,2,4,5,6,1.25\n");
  run = import_table(file, {});
  EXPECT_TRUE(std::isnan(run.header.radius[0]));
  EXPECT_EQ(run.header.radius[1], 1.25);
  options = {};
  options.radius = 1.0;
  const std::string msg = import_error(read_text(file), options);
  EXPECT_NE(msg.find("--radius"), std::string::npos) << msg;
}

// 2,000 rows, each a new frame and a new particle: a dense store of 4e6 slots, 0.05 %
// filled, refused before it is made; a coordinate that overflows when scaled to voxels too.
TEST_F(ImportTable, LabelsThatNeverRepeatAndOverflowingCoordinatesAreRefused) {
  std::string csv = "frame,particle,x,y,z\n";
  for (int r = 0; r < 2000; ++r)
    csv += std::to_string(r) + "," + std::to_string(r) + ",1,2,3\n";
  expect_error(csv, "2000 rows label 2000 frames x 2000 particles, of which 0.05 %");
  // As many slots, but every particle in every frame: accepted.
  std::string dense = "frame,particle,x,y,z\n";
  for (int t = 0; t < 2; ++t)
    for (int p = 0; p < 1000; ++p)
      dense += std::to_string(t) + "," + std::to_string(p) + ",1,2,3\n";
  write_text(path("dense.csv"), dense);
  EXPECT_EQ(import_table(path("dense.csv"), ImportOptions{}).frames.size(), 2u);
  ImportOptions voxels;
  voxels.length_unit = "voxel";
  voxels.voxel_size = Eigen::Vector3d(10, 10, 10);
  voxels.voxel_size_unit = "um";
  expect_error("frame,particle,x,y,z\n0,1,1e308,2,3\n", "beyond a double's range", voxels);
}

TEST_F(ImportTable, MissingRequiredColumnIsNamed) {
  expect_error("frame,particle,x,y\n0,1,1,2\n", "'z'");
  expect_error("frame,x,y,z\n0,1,1,2\n", "'particle'");
  expect_error("frame,particle,x,y,z,ax\n0,1,1,2,3,1\n", "ax, ay, az");
  expect_error("frame,particle,x,y,z\n# no rows\n", "no rows");
}

TEST_F(ImportTable, BadCoordinatesNameTheLine) {
  expect_error("frame,particle,x,y,z\n0,1,1,2,3\n0,2,1,abc,3\n", "line 3, column 'y'");
  expect_error("frame,particle,x,y,z\n0,1,nan,2,3\n", "line 2, column 'x'");
  expect_error("frame,particle,x,y,z\n0,1,1,2,3\n# c\n1,1,1,2,\n", "line 4, column 'z'");
  expect_error("frame,particle,x,y,z\n0,1,1,inf,3\n", "line 2, column 'y'");
  expect_error("frame,particle,x,y,z\n0,1,1,2,3\n0,2,1,2\n", "line 3");
}

TEST_F(ImportTable, SameParticleTwiceInAFrameNamesBothLines) {
  const std::string msg =
      import_error("frame,particle,x,y,z\n0,7,1,1,1\n0,8,2,2,2\n1,7,3,3,3\n0,7,4,4,4\n");
  EXPECT_NE(msg.find("line 5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle 7 appears twice in frame 0"), std::string::npos) << msg;
}

TEST_F(ImportTable, BadAxesNameTheLine) {
  const std::string head = "frame,particle,x,y,z,ax,ay,az\n0,1,1,1,1,1,0,0\n";
  expect_error(head + "1,1,1,1,1,0,0,0\n", "line 3: axis (ax,ay,az) has zero length");
  expect_error(head + "1,1,1,1,1,1,,0\n", "line 3: axis (ax,ay,az) must be three finite");
  expect_error(head + "1,1,1,1,1,nan,0,1\n", "line 3: axis (ax,ay,az) must be three finite");
  expect_error(head + "1,1,1,1,1,1,inf,0\n", "line 3: axis");
  // An axis empty (or nan) in all three columns is "not seen": NaN, no error.
  const auto file = path("ok.csv");
  write_text(file, head + "1,1,1,1,1,,,\n2,1,1,1,1,nan,nan,nan\n");
  const Trajectories run = import_table(file, {});
  expect_row(run.frames[0].axis, 0, 1, 0, 0);
  expect_nan_row(run.frames[1].axis, 0);
  expect_nan_row(run.frames[2].axis, 0);
}

// Orientations as trajectory_table writes them (qw, qx, qy, qz): a unit quaternion per
// row, stored normalised; all four empty where unknown; anything else names the line.
TEST_F(ImportTable, OrientationsAreUnitQuaternions) {
  const std::string head = "frame,particle,x,y,z,qw,qx,qy,qz\n0,1,1,1,1,0,0.6,0,0.8\n";
  const auto file = path("ok.csv");
  write_text(file, head + "1,1,1,1,1,,,,\n");
  const Trajectories run = import_table(file, {});
  ASSERT_TRUE(run.header.has_orientation);
  EXPECT_EQ(run.frames[0].orientation.row(0), Eigen::RowVector4d(0, 0.6, 0, 0.8));
  EXPECT_TRUE(run.frames[1].orientation.row(0).array().isNaN().all());
  expect_error(head + "1,1,1,1,1,1,0,0,0.1\n", "line 3: orientation (qw,qx,qy,qz) must be a unit");
  expect_error(head + "1,1,1,1,1,1,,0,0\n", "line 3: orientation");
  expect_error("frame,particle,x,y,z,qw,qx,qy\n0,1,1,1,1,1,0,0\n",
               "all four columns qw, qx, qy, qz");
}

TEST_F(ImportTable, BadLabelsNameTheLine) {
  expect_error("frame,particle,x,y,z\n0,1,1,1,1\n1.5,1,1,1,1\n", "line 3, column 'frame'");
  expect_error("frame,particle,x,y,z\n,1,1,1,1\n", "line 2, column 'frame'");
  expect_error("frame,particle,x,y,z\n0,2.25,1,1,1\n", "line 2, column 'particle'");
  expect_error("frame,particle,x,y,z\nzero,1,1,1,1\n", "line 2, column 'frame'");
}

TEST_F(ImportTable, BadFlagsAndRadiiNameTheLine) {
  const std::string head = "frame,particle,x,y,z,hole_contact\n0,1,1,1,1,1\n";
  expect_error(head + "0,2,1,1,1,2\n", "line 3, column 'hole_contact'");
  expect_error(head + "0,2,1,1,1,0.5\n", "line 3, column 'hole_contact'");
  expect_error(head + "0,2,1,1,1,\n", "line 3, column 'hole_contact'");
  expect_error("frame,particle,x,y,z,radius\n0,1,1,1,1,-2\n", "line 2, column 'radius'");
  expect_error("frame,particle,x,y,z,radius\n0,1,1,1,1,0\n", "line 2, column 'radius'");
  expect_error("frame,particle,x,y,z,ep\n0,1,1,1,1,-0.1\n", "line 2, column 'ep'");
  expect_error("frame,particle,x,y,z,axis_error\n0,1,1,1,1,inf\n", "line 2, column 'axis_error'");
  expect_error("frame,particle,x,y,z,ep_x,ep_y\n0,1,1,1,1,1,1\n", "all three columns ep_x");
  expect_error("frame,particle,x,y,z,ep,ep_x,ep_y,ep_z\n0,1,1,1,1,1,1,1,1\n", "not both");
}

TEST_F(ImportTable, BadOptionsAreErrors) {
  const std::string csv = "frame,particle,x,y,z\n0,1,1,1,1\n";
  ImportOptions no_unit;
  no_unit.voxel_size = Eigen::Vector3d(1, 1, 1);
  EXPECT_NE(import_error(csv, no_unit).find("--voxel-size"), std::string::npos);
  ImportOptions voxel_unit = no_unit;
  voxel_unit.voxel_size_unit = "voxel";
  EXPECT_NE(import_error(csv, voxel_unit).find("--voxel-size"), std::string::npos);
  ImportOptions unknown_unit = no_unit;
  unknown_unit.voxel_size_unit = "inch";
  EXPECT_NE(import_error(csv, unknown_unit).find("--voxel-size"), std::string::npos);
  ImportOptions physical_table = no_unit;
  physical_table.voxel_size_unit = "mm";
  physical_table.length_unit = "mm";
  EXPECT_NE(import_error(csv, physical_table).find("--voxel-size"), std::string::npos);
  ImportOptions zero_size = no_unit;
  zero_size.voxel_size_unit = "mm";
  zero_size.voxel_size = Eigen::Vector3d(1, 0, 1);
  EXPECT_NE(import_error(csv, zero_size).find("--voxel-size"), std::string::npos);
  ImportOptions bad_length;
  bad_length.length_unit = "inch";
  EXPECT_NE(import_error(csv, bad_length).find("'inch'"), std::string::npos);
  ImportOptions bad_radius;
  bad_radius.radius = -1.0;
  EXPECT_NE(import_error(csv, bad_radius).find("--radius"), std::string::npos);
  // The control: the same table imports with good options.
  ImportOptions good = no_unit;
  good.voxel_size_unit = "mm";
  const auto file = path("good.csv");
  write_text(file, csv);
  EXPECT_EQ(import_table(file, good).header.length_unit, "mm");
}

// validate() alone, before any table: the defaults pass, a bad option is one line naming it.
TEST(ImportOptions, ValidateNamesTheBadOptionAndPassesTheDefaults) {
  using granmem::testing::error_message;
  EXPECT_NO_THROW(ImportOptions{}.validate());
  ImportOptions unit;
  unit.length_unit = "inch";
  EXPECT_EQ(error_message([&] { unit.validate(); }),
            "--length-unit 'inch': expected one of m, cm, mm, um, voxel");
  ImportOptions lengths;
  lengths.length_unit = "mm";
  lengths.voxel_size = Eigen::Vector3d(1, 1, 1);
  lengths.voxel_size_unit = "mm";
  EXPECT_EQ(error_message([&] { lengths.validate(); }),
            "--voxel-size applies to voxel coordinates, but --length-unit is mm");
  ImportOptions size;
  size.voxel_size = Eigen::Vector3d(1, std::nan(""), 1);
  size.voxel_size_unit = "mm";
  EXPECT_EQ(error_message([&] { size.validate(); }), "--voxel-size: expected three positive sizes");
  size.voxel_size = Eigen::Vector3d(0.05, 0.05, 0.075);
  EXPECT_NO_THROW(size.validate());
  ImportOptions radius;
  radius.radius = 0.0;
  EXPECT_EQ(error_message([&] { radius.validate(); }), "--radius: expected a positive radius");
}

// TrackMate's spot table: its own column names, quoted, three rows of names and units
// under the header, text columns; mapped onto granmem's with CsvReadOptions.
TEST_F(ImportTable, TrackMatesSpotTableWithItsColumnNames) {
  const auto file = path("spots.csv");
  write_text(file,
             "\"LABEL\",\"ID\",\"TRACK_ID\",\"QUALITY\",\"POSITION_X\",\"POSITION_Y\","
             "\"POSITION_Z\",\"FRAME\"\r\n"
             "Label,Spot ID,Track ID,Quality,X,Y,Z,Frame\r\n"
             "Label,Spot ID,Track ID,Quality,X,Y,Z,Frame\r\n"
             ",,,(quality),(micron),(micron),(micron),\r\n"
             "\"ID7, first\",7,0,31.2,10.5,20.25,3.0,0\r\n"
             "ID8,8,1,30.0,40.0,20.0,3.5,0\r\n"
             "ID9,9,0,29.1,10.75,20.5,3.25,1\r\n");
  ImportOptions o;
  o.length_unit = "um";
  o.csv.rename = {{"FRAME", "frame"},
                  {"TRACK_ID", "particle"},
                  {"POSITION_X", "x"},
                  {"POSITION_Y", "y"},
                  {"POSITION_Z", "z"}};
  o.csv.skip_rows = 3;
  ImportSummary sum;
  const Trajectories run = import_table(file, o, &sum);
  EXPECT_EQ(sum.rows, 3u);
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{0, 1}));
  ASSERT_EQ(run.frames.size(), 2u);
  EXPECT_EQ(run.frames[1].position(0, 0), 10.75);
  EXPECT_EQ(run.frames[0].position(1, 2), 3.5);
  EXPECT_TRUE(std::isnan(run.frames[1].position(1, 0)));  // track 1 not in frame 1

  // Without skipping the rows of names the first is not a number, and says where.
  o.csv.skip_rows = 0;
  try {
    import_table(file, o);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2, column 'frame': expected a number, found "
                                         "'Frame'"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(ImportTable, TabSeparatedTablesAreRead) {
  const auto file = path("t.tsv");
  write_text(file, "frame\tparticle\tx\ty\tz\n0\t5\t1.5\t2\t3\n1\t5\t1.75\t2\t3\n");
  const Trajectories run = import_table(file, ImportOptions{});
  ASSERT_EQ(run.frames.size(), 2u);
  EXPECT_EQ(run.frames[1].position(0, 0), 1.75);
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{5}));
}

}  // namespace
}  // namespace granmem
