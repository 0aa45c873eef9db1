// End to end: `granmem import` a hand-written table, `granmem analyze` it, and check every
// number of the outputs against values worked out by hand.

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "granmem/core/hdf5.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
const double kNaN = std::nan("");

// Compares a column with expected values: exactly (tolerance 0, NaN equal to NaN) or
// within a tolerance (trigonometry).
void expect_column(const Table& t, const std::string& name, const std::vector<double>& expected,
                   double tolerance = 0) {
  SCOPED_TRACE("column " + name);
  const std::vector<double>& v = t[name].values;
  ASSERT_EQ(v.size(), expected.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    SCOPED_TRACE("row " + std::to_string(i));
    if (std::isnan(expected[i])) {
      EXPECT_TRUE(std::isnan(v[i])) << v[i];
    } else if (tolerance == 0) {
      EXPECT_EQ(v[i], expected[i]);
    } else {
      EXPECT_NEAR(v[i], expected[i], tolerance);
    }
  }
}

const std::vector<std::string> kDisplacementColumns = {
    "frame", "particle", "dx", "dy", "dz", "dr", "theta_axis_deg", "rot_disp"};
const std::vector<std::string> kPerFrameColumns = {"frame",
                                                   "n",
                                                   "mean_dr",
                                                   "median_dr",
                                                   "mean_theta_axis_deg",
                                                   "mean_rot_disp",
                                                   "median_theta_axis_deg",
                                                   "median_rot_disp",
                                                   "n_rot",
                                                   "msd",
                                                   "drift_x",
                                                   "drift_y",
                                                   "drift_z",
                                                   "prev_frame",
                                                   "packing_fraction",
                                                   "coordination"};

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names)
    s += (s.empty() ? "" : ",") + n;
  return s;
}

// Three frames in mm, columns in an unusual order, rows not in frame order. Four grains:
//   10: (0,0,0) -> (3,4,0) -> (3,4,12); axis z -> x (90 deg) -> (-3,-3,0) (45 deg); radius 2
//   20: (10,10,10) -> (10,10,11) -> same; axis (0,0,2) -> (0,0,-5) -> (0,0,-1): sign flips, 0 deg;
//       radius 1.5; touches a neighbour through its hole in frame 1
//   30: seen in frames 0 and 2 only (axis unseen in frame 0): no displacement rows at all
//   40: (30,30,30) -> (30,30,28) -> (31,30,28); axis y -> (0,1,1) (45 deg) -> (0,-2,-2) (0 deg)
const char* kTable =
    "# tracked by hand\n"
    "hole_contact,radius,z,particle,ax,x,frame,az,y,ay\n"
    "0,2,12,10,-3,3,2,0,4,-3\n"
    "0,1.5,11,20,0,10,2,-1,10,0\n"
    "0,1,20,30,1,21,2,0,20,0\n"
    "0,1,28,40,0,31,2,-2,30,-2\n"
    "0,2,0,10,0,0,0,1,0,0\n"
    "0,1.5,10,20,0,10,0,2,10,0\n"
    "0,1,20,30,,20,0,,20,\n"
    "0,1,30,40,0,30,0,0,30,1\n"
    "0,2,0,10,1,3,1,0,4,0\n"
    "1,1.5,11,20,0,10,1,-5,10,0\n"
    "0,1,28,40,0,30,1,1,30,1\n";

class ImportAnalyzeTest : public GranmemTest {
 protected:
  // Imports kTable (mm) into work/run.h5.
  void import_table(const std::vector<std::string>& extra = {}) {
    write_text(in_work("grains.csv"), kTable);
    std::vector<std::string> args = {"import", "grains.csv",    "--out",
                                     "run.h5", "--length-unit", "mm"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = granmem_ok(args);
    EXPECT_NE(
        r.out.find("imported 11 rows of grains.csv (csv): 3 frames, 4 grains, 1 missing (grain, "
                   "frame) entries, cavity axis in 10 rows"),
        std::string::npos)
        << r.out;
    EXPECT_EQ(r.err, "");
  }
  Table displacements(const std::string& dir) const {
    return read_columns(in_work(dir) / "displacements.csv", kDisplacementColumns);
  }
  Table per_frame(const std::string& dir) const {
    return read_columns(in_work(dir) / "per_frame.csv", kPerFrameColumns);
  }
};

TEST_F(ImportAnalyzeTest, DisplacementsAndAxisAnglesByHand) {
  import_table();
  const RunResult r = granmem_ok({"analyze", "run.h5", "--out", "out"});
  EXPECT_NE(r.out.find("run.h5: 6 displacements over 2 frame pairs, lengths in mm"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.err, "");

  const fs::path csv = in_work("out") / "displacements.csv";
  EXPECT_EQ(csv_header(csv), join(kDisplacementColumns));
  EXPECT_NE(read_text(csv).find("\n# displacement of each grain from frame prev to frame; "
                                "lengths in mm, angles in degrees\n"),
            std::string::npos);

  const Table d = displacements("out");
  // Grain 30 is missing in frame 1: no rows for frames 1 and 2.
  expect_column(d, "frame", {1, 1, 1, 2, 2, 2});
  expect_column(d, "particle", {10, 20, 40, 10, 20, 40});
  expect_column(d, "dx", {3, 0, 0, 0, 0, 1});
  expect_column(d, "dy", {4, 0, 0, 0, 0, 0});
  expect_column(d, "dz", {0, 1, -2, 12, 0, 0});
  expect_column(d, "dr", {5, 1, 2, 12, 0, 1});
  // 90 deg, a sign-flipped axis (0), 45 deg; then 45 deg (axis of any length and sign), 0, 0.
  expect_column(d, "theta_axis_deg", {90, 0, 45, 45, 0, 0}, 1e-12);
  // theta in radians times the radius.
  expect_column(d, "rot_disp", {kPi / 2 * 2, 0, kPi / 4 * 1, kPi / 4 * 2, 0, 0}, 1e-12);
}

TEST_F(ImportAnalyzeTest, PerFrameMeansAndMediansByHand) {
  import_table();
  granmem_ok({"analyze", "run.h5", "--out", "out"});
  const fs::path csv = in_work("out") / "per_frame.csv";
  EXPECT_EQ(csv_header(csv), join(kPerFrameColumns));
  const Table p = per_frame("out");
  expect_column(p, "frame", {1, 2});
  expect_column(p, "prev_frame", {0, 1});
  expect_column(p, "n", {3, 3});
  expect_column(p, "mean_dr", {(5.0 + 1 + 2) / 3, (12.0 + 0 + 1) / 3});
  expect_column(p, "median_dr", {2, 1});
  expect_column(p, "msd", {(25.0 + 1 + 4) / 3, (144.0 + 0 + 1) / 3});
  expect_column(p, "mean_theta_axis_deg", {45, 15}, 1e-12);
  expect_column(p, "median_theta_axis_deg", {45, 0}, 1e-12);
  expect_column(p, "mean_rot_disp", {(kPi + kPi / 4) / 3, kPi / 2 / 3}, 1e-12);
  expect_column(p, "median_rot_disp", {kPi / 4, 0}, 1e-12);
  expect_column(p, "n_rot", {3, 3});
  // Without --subtract-drift the drift is reported, not removed.
  expect_column(p, "drift_x", {3.0 / 3, 1.0 / 3});
  expect_column(p, "drift_y", {4.0 / 3, 0});
  expect_column(p, "drift_z", {(0.0 + 1 - 2) / 3, 12.0 / 3});
}

TEST_F(ImportAnalyzeTest, WritesPdfsAndTheSameTablesToAnalysisH5) {
  import_table();
  granmem_ok({"analyze", "run.h5", "--out", "out"});
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(in_work("out")))
    names.insert(e.path().filename().string());
  EXPECT_EQ(names,
            (std::set<std::string>{"analysis.h5", "displacements.csv", "per_frame.csv",
                                   "pdf_dr.csv", "pdf_rot_disp.csv", "pdf_theta_axis_deg.csv"}));
  // Default pdfs: 50 linear bins over the data's range, all six values counted.
  for (const std::string q : {"dr", "theta_axis_deg", "rot_disp"}) {
    SCOPED_TRACE(q);
    const fs::path pdf = in_work("out") / ("pdf_" + q + ".csv");
    EXPECT_EQ(csv_header(pdf), "bin_lo,bin_hi,bin_center,count,density");
    const Table t = read_columns(pdf, {"bin_lo", "bin_hi", "count", "density"});
    ASSERT_EQ(t.rows(), 50u);
    double count = 0, integral = 0;
    for (std::size_t i = 0; i < t.rows(); ++i) {
      count += t["count"].values[i];
      integral += t["density"].values[i] * (t["bin_hi"].values[i] - t["bin_lo"].values[i]);
    }
    EXPECT_EQ(count, 6);
    EXPECT_NEAR(integral, 1, 1e-12);
  }
  EXPECT_EQ(read_columns(in_work("out") / "pdf_dr.csv", {"bin_lo"})["bin_lo"].values.front(), 0);

  // A second analysis into the folder with other pdfs leaves none of the first's behind.
  write_text(in_work("out") / "notes.txt", "mine");
  granmem_ok({"analyze", "run.h5", "--out", "out", "--pdf", "dz"});
  names.clear();
  for (const auto& e : fs::directory_iterator(in_work("out")))
    names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"analysis.h5", "displacements.csv", "per_frame.csv",
                                          "pdf_dz.csv", "notes.txt"}));
  granmem_ok({"analyze", "run.h5", "--out", "out"});

  // analysis.h5 holds the same tables, with units.
  const h5::File f = h5::File::open(in_work("out") / "analysis.h5");
  const Table d = h5::read_table(f, "/displacements");
  const Table csv = displacements("out");
  for (const std::string& c : kDisplacementColumns) {
    SCOPED_TRACE(c);
    expect_column(d, c, csv[c].values);
  }
  EXPECT_EQ(d["dx"].unit, "mm");
  EXPECT_EQ(d["theta_axis_deg"].unit, "deg");
  const Table p = h5::read_table(f, "/per_frame");
  expect_column(p, "mean_dr", per_frame("out")["mean_dr"].values);
  EXPECT_TRUE(h5::exists(f.id(), "/pdf/dr/density"));
  const h5::Handle params = h5::open_group(f, "/parameters/analyze");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "hole-contacts"), "keep");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "pdf-bins"), "50");
}

TEST_F(ImportAnalyzeTest, PdfOptionsBinsRangeFramesAndLogScale) {
  import_table();
  // dr of frames 1 and 2: 5, 1, 2, 12, 0, 1. Four bins of width 3 over 0:12.
  granmem_ok({"analyze", "run.h5", "--out", "lin", "--pdf", "dr", "--pdf-bins", "4", "--pdf-range",
              "0:12", "--window", "1:2"});
  EXPECT_FALSE(fs::exists(in_work("lin") / "pdf_theta_axis_deg.csv"));
  const Table lin = read_columns(in_work("lin") / "pdf_dr.csv",
                                 {"bin_lo", "bin_hi", "bin_center", "count", "density"});
  expect_column(lin, "bin_lo", {0, 3, 6, 9});
  expect_column(lin, "bin_hi", {3, 6, 9, 12});
  expect_column(lin, "bin_center", {1.5, 4.5, 7.5, 10.5});
  expect_column(lin, "count", {4, 1, 0, 1});
  expect_column(lin, "density", {4.0 / 18, 1.0 / 18, 0, 1.0 / 18});
  EXPECT_NE(read_text(in_work("lin") / "pdf_dr.csv").find("over frames 1 to 2"), std::string::npos);

  // Only frame 2 (12, 0, 1), log bins 1:4:16; the zero counts in the normalisation only.
  granmem_ok({"analyze", "run.h5", "--out", "log", "--pdf", "dr,dz", "--pdf-bins", "2",
              "--pdf-range", "1:16", "--pdf-scale", "log", "--window", "2:2"});
  const Table log = read_columns(in_work("log") / "pdf_dr.csv",
                                 {"bin_lo", "bin_hi", "bin_center", "count", "density"});
  expect_column(log, "bin_lo", {1, 4});
  expect_column(log, "bin_hi", {4, 16});
  expect_column(log, "bin_center", {2, 8});
  expect_column(log, "count", {1, 1});
  expect_column(log, "density", {1.0 / (3 * 3), 1.0 / (3 * 12)});
  // dz of frame 2: 12, 0, 0.
  const Table dz = read_columns(in_work("log") / "pdf_dz.csv", {"count"});
  expect_column(dz, "count", {0, 1});
}

TEST_F(ImportAnalyzeTest, HoleContactPolicies) {
  import_table();
  // Grain 20 touches through its hole in frame 1: both its pairs (0->1, 1->2) are flagged.
  granmem_ok({"analyze", "run.h5", "--out", "rot", "--hole-contacts", "exclude-rotations"});
  const Table d = displacements("rot");
  expect_column(d, "particle", {10, 20, 40, 10, 20, 40});
  expect_column(d, "dr", {5, 1, 2, 12, 0, 1});  // translations kept
  expect_column(d, "theta_axis_deg", {90, kNaN, 45, 45, kNaN, 0}, 1e-12);
  expect_column(d, "rot_disp", {kPi, kNaN, kPi / 4, kPi / 2, kNaN, 0}, 1e-12);
  const Table p = per_frame("rot");
  expect_column(p, "n", {3, 3});
  expect_column(p, "n_rot", {2, 2});
  expect_column(p, "mean_theta_axis_deg", {67.5, 22.5}, 1e-12);
  expect_column(p, "mean_dr", {(5.0 + 1 + 2) / 3, (12.0 + 0 + 1) / 3});

  granmem_ok({"analyze", "run.h5", "--out", "ex", "--hole-contacts", "exclude"});
  const Table e = displacements("ex");
  expect_column(e, "particle", {10, 40, 10, 40});
  expect_column(e, "dr", {5, 2, 12, 1});
  const Table pe = per_frame("ex");
  expect_column(pe, "n", {2, 2});
  expect_column(pe, "mean_dr", {3.5, 6.5});
  expect_column(pe, "median_dr", {3.5, 6.5});
}

TEST_F(ImportAnalyzeTest, WallDistanceWithTheImportedBoxOrAGivenBox) {
  import_table({"--container", "0,0,0,40,40,40"});
  // 5 mm: grain 10 starts on the wall (0,0,0), so only 20 and 40 remain.
  granmem_ok({"analyze", "run.h5", "--out", "w5", "--wall-distance", "5"});
  expect_column(displacements("w5"), "particle", {20, 40, 20, 40});
  // 0.95 cm = 9.5 mm: grain 40 at x = 31 in frame 2 is 9 mm from the wall x = 40.
  granmem_ok({"analyze", "run.h5", "--out", "w95", "--wall-distance", "0.95cm"});
  const Table d = displacements("w95");
  expect_column(d, "frame", {1, 1, 2});
  expect_column(d, "particle", {20, 40, 20});
  // A larger box given to analyze replaces the run's box: every grain is far from its walls.
  granmem_ok({"analyze", "run.h5", "--out", "big", "--wall-distance", "5", "--container",
              "-100,-100,-100,100,100,100"});
  expect_column(displacements("big"), "particle", {10, 20, 40, 10, 20, 40});
}

TEST_F(GranmemTest, AxesOfAnyLength) {
  // Axis lengths far from 1: their squares would overflow or underflow a double.
  write_text(in_work("axes.csv"),
             "frame,particle,x,y,z,ax,ay,az,radius\n"
             "0,1,0,0,0,1e200,0,0,1\n0,2,5,0,0,1e-200,0,0,1\n0,3,9,0,0,0,0,-7,1\n"
             "1,1,0,0,0,0,-1e200,0,1\n1,2,5,0,0,1e-200,1e-200,0,1\n1,3,9,0,0,0,0.5,0,1\n");
  const RunResult r = granmem_ok({"import", "axes.csv", "--out", "run.h5", "--length-unit", "mm"});
  EXPECT_NE(r.out.find("cavity axis in 6 rows"), std::string::npos) << r.out;
  granmem_ok({"analyze", "run.h5", "--out", "out"});
  const Table d = read_columns(in_work("out") / "displacements.csv",
                               {"particle", "theta_axis_deg", "rot_disp"});
  expect_column(d, "particle", {1, 2, 3});
  expect_column(d, "theta_axis_deg", {90, 45, 90}, 1e-12);
  expect_column(d, "rot_disp", {kPi / 2, kPi / 4, kPi / 2}, 1e-12);
}

TEST_F(GranmemTest, SubtractDriftOfAPureTranslationGivesZero) {
  // Three grains translated rigidly by (0.5,-1.25,2) then (0.25,0.25,-0.5), in cm.
  write_text(in_work("shift.csv"),
             "frame,particle,x,y,z\n"
             "0,1,1,2,3\n0,2,4.5,0.25,7\n0,3,-2,8,1.5\n"
             "1,1,1.5,0.75,5\n1,2,5,-1,9\n1,3,-1.5,6.75,3.5\n"
             "2,1,1.75,1,4.5\n2,2,5.25,-0.75,8.5\n2,3,-1.25,7,3\n");
  granmem_ok({"import", "shift.csv", "--out", "run.h5", "--length-unit", "cm"});
  granmem_ok({"analyze", "run.h5", "--out", "raw"});
  const Table raw = read_columns(in_work("raw") / "displacements.csv", {"dx", "dy", "dz", "dr"});
  expect_column(raw, "dx", {0.5, 0.5, 0.5, 0.25, 0.25, 0.25});
  expect_column(raw, "dy", {-1.25, -1.25, -1.25, 0.25, 0.25, 0.25});
  const double dr1 = std::sqrt(0.25 + 1.5625 + 4), dr2 = std::sqrt(0.0625 + 0.0625 + 0.25);
  expect_column(raw, "dr", {dr1, dr1, dr1, dr2, dr2, dr2}, 1e-15);
  EXPECT_NE(read_text(in_work("raw") / "displacements.csv").find("lengths in cm"),
            std::string::npos);

  granmem_ok({"analyze", "run.h5", "--out", "rel", "--subtract-drift"});
  const Table d = read_columns(in_work("rel") / "displacements.csv",
                               {"frame", "dx", "dy", "dz", "dr", "theta_axis_deg"});
  expect_column(d, "frame", {1, 1, 1, 2, 2, 2});
  for (const char* c : {"dx", "dy", "dz", "dr"})
    expect_column(d, c, std::vector<double>(6, 0));
  expect_column(d, "theta_axis_deg", std::vector<double>(6, kNaN));  // the run has no axes
  const Table p =
      read_columns(in_work("rel") / "per_frame.csv",
                   {"n", "mean_dr", "median_dr", "msd", "drift_x", "drift_y", "drift_z"});
  expect_column(p, "n", {3, 3});
  expect_column(p, "mean_dr", {0, 0});
  expect_column(p, "median_dr", {0, 0});
  expect_column(p, "msd", {0, 0});
  expect_column(p, "drift_x", {0.5, 0.25});
  expect_column(p, "drift_y", {-1.25, 0.25});
  expect_column(p, "drift_z", {2, -0.5});
  // Without axes only the pdf of dr.
  EXPECT_TRUE(fs::exists(in_work("rel") / "pdf_dr.csv"));
  EXPECT_FALSE(fs::exists(in_work("rel") / "pdf_theta_axis_deg.csv"));
}

TEST_F(GranmemTest, AnisotropicVoxelSizeGivesPhysicalDisplacementsAndAngles) {
  // Voxels of 0.5 x 0.5 x 2 mm. Grain 1 moves (2,4,1) voxels = (1,2,2) mm, |d| = 3 mm; its
  // axis (0,0,1) -> (4,0,1) in voxels is (0,0,2) -> (2,0,2) in mm: 45 deg (not the 76 deg
  // the voxel directions make). Radius 4 voxels = 2 mm (x size). Grain 2 moves 3 voxels in z.
  write_text(in_work("voxels.csv"),
             "frame,particle,x,y,z,ax,ay,az,radius\n"
             "0,1,2,4,1,0,0,1,4\n0,2,10,10,10,1,0,0,4\n"
             "1,1,4,8,2,4,0,1,4\n1,2,10,10,13,-1,0,0,4\n");
  const RunResult imp = granmem_ok({"import", "voxels.csv", "--out", "run.h5", "--length-unit",
                                    "voxel", "--voxel-size", "0.5,0.5,2mm"});
  EXPECT_NE(imp.out.find("lengths in mm"), std::string::npos) << imp.out;

  const RunResult info = granmem_ok({"info", "run.h5"});
  EXPECT_NE(info.out.find("  lengths     mm, voxel size (0.5, 0.5, 2) mm\n"), std::string::npos)
      << info.out;
  EXPECT_NE(info.out.find("  grains      2, mean radius 2 mm\n"), std::string::npos) << info.out;

  granmem_ok({"analyze", "run.h5", "--out", "out"});
  const fs::path csv = in_work("out") / "displacements.csv";
  EXPECT_NE(read_text(csv).find("lengths in mm"), std::string::npos);
  const Table d = read_columns(csv, kDisplacementColumns);
  expect_column(d, "particle", {1, 2});
  expect_column(d, "dx", {1, 0});
  expect_column(d, "dy", {2, 0});
  expect_column(d, "dz", {2, 6});
  expect_column(d, "dr", {3, 6});
  expect_column(d, "theta_axis_deg", {45, 0}, 1e-12);
  expect_column(d, "rot_disp", {kPi / 4 * 2, 0}, 1e-12);

  // One size for all three axes, in cm: lengths in cm.
  granmem_ok({"import", "voxels.csv", "--out", "iso.h5", "--voxel-size", "0.1cm"});
  granmem_ok({"analyze", "iso.h5", "--out", "iso"});
  const fs::path iso = in_work("iso") / "displacements.csv";
  EXPECT_NE(read_text(iso).find("lengths in cm"), std::string::npos);
  expect_column(read_columns(iso, {"dz"}), "dz", {0.1, 0.1 * 3}, 1e-15);
}

TEST_F(GranmemTest, SampleDataEndToEnd) {
  const std::string data = GRANMEM_SAMPLE_DATA;
  const std::string config = data + "/sample.toml";
  const RunResult imp =
      granmem_ok({"--config", config, "import", data + "/tracked_grains.csv", "--out", "run.h5"});
  EXPECT_NE(imp.out.find("16 frames, 800 grains"), std::string::npos) << imp.out;
  EXPECT_NE(imp.out.find("lengths in mm"), std::string::npos) << imp.out;
  EXPECT_TRUE(fs::exists(in_work("run.xmf")));

  const RunResult info = granmem_ok({"info", "run.h5"});
  EXPECT_NE(info.out.find("  frames      16 (steps 0 to 15)"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("  box         lower (0, 0, 0), edges (52, 52, 42) mm"),
            std::string::npos)
      << info.out;

  granmem_ok({"--config", config, "analyze", "run.h5", "--out", "analysis"});
  const Table p = read_columns(in_work("analysis") / "per_frame.csv",
                               {"frame", "n", "mean_dr", "median_dr", "prev_frame"});
  ASSERT_EQ(p.rows(), 15u);
  for (std::size_t r = 0; r < p.rows(); ++r) {
    EXPECT_EQ(p["frame"].values[r], double(r + 1));
    EXPECT_EQ(p["prev_frame"].values[r], double(r));
    EXPECT_GT(p["n"].values[r], 0);
    EXPECT_TRUE(std::isfinite(p["mean_dr"].values[r]));
    EXPECT_GT(p["mean_dr"].values[r], 0);
  }
  // The packing settles: grains move less in the last cycle than in the first.
  EXPECT_GT(p["mean_dr"].values.front(), p["mean_dr"].values.back());
  // The config's [analyze] section: 30 log bins pooled over frames 6 to 15.
  const fs::path pdf = in_work("analysis") / "pdf_dr.csv";
  EXPECT_EQ(read_columns(pdf, {"count"}).rows(), 30u);
  EXPECT_NE(read_text(pdf).find("over frames 6 to 15"), std::string::npos);
}

}  // namespace
}  // namespace granmem::testing
