#include "granmem/rotation/motion_analysis.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"
#include "granmem/rotation/analyze_run.hpp"
#include "temp_dir.hpp"

#include "checks.hpp"

namespace granmem {
namespace {

using testing::error_message;
using testing::pdf_integral;
using testing::pdf_total_count;
using testing::same_number;

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = M_PI / 180;

void set_orientation(Frame& f, Eigen::Index grain, const Eigen::Quaterniond& q) {
  f.orientation.row(grain) << q.w(), q.x(), q.y(), q.z();
}

Eigen::Quaterniond turn(double degrees, const Eigen::Vector3d& about) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kDeg, about));
}

// Three simulated grains (ids 10, 20, 30; radii 0.5, 1, 2 mm) over frames labelled 100,
// 105, 107. Displacements are small integer vectors, so every length is exact:
//   100 -> 105: grain 10 moves (3,4,0) and tilts 90 deg about x (axis 90, full 90)
//               grain 20 moves (0,0,2) and spins 60 deg about z (axis 0, full 60)
//               grain 30 moves (1,2,2) and tilts 30 deg about y (axis 30, full 30)
//   105 -> 107: grain 10 moves (0,0,-4) and does not turn
//               grain 20 is lost (NaN position and orientation)
//               grain 30 moves (2,-1,2) and tilts 20 deg more about y
Trajectories three_grain_run() {
  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = "mm";
  h.id = {10, 20, 30};
  h.radius = {0.5, 1.0, 2.0};
  h.has_orientation = true;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();

  Frame f0 = Frame::unknown(h);
  f0.step = 100;
  f0.time = 0;
  f0.position << 0, 0, 0,  //
      10, 0, 0,            //
      0, 10, 0;
  for (Eigen::Index i = 0; i < 3; ++i)
    set_orientation(f0, i, Eigen::Quaterniond::Identity());

  Frame f1 = Frame::unknown(h);
  f1.step = 105;
  f1.time = 1;
  f1.position << 3, 4, 0,  //
      10, 0, 2,            //
      1, 12, 2;
  set_orientation(f1, 0, turn(90, x));
  set_orientation(f1, 1, turn(60, z));
  set_orientation(f1, 2, turn(30, y));

  Frame f2 = Frame::unknown(h);
  f2.step = 107;
  f2.time = 2;
  f2.position << 3, 4, -4,  //
      kNaN, kNaN, kNaN,     //
      3, 11, 4;
  set_orientation(f2, 0, turn(90, x));
  set_orientation(f2, 2, turn(50, y));

  run.frames = {f0, f1, f2};
  return run;
}

// The same three grains and motions with nothing known about their rotation.
Trajectories translation_only_run() {
  Trajectories run = three_grain_run();
  run.header.has_orientation = false;
  for (Frame& f : run.frames)
    f.orientation.resize(0, 4);
  return run;
}

std::vector<std::string> column_names(const Table& t) {
  std::vector<std::string> names;
  for (const Column& c : t.columns())
    names.push_back(c.name);
  return names;
}

void expect_same_values(const Table& read, const Table& expected, const std::string& what) {
  ASSERT_EQ(column_names(read), column_names(expected)) << what;
  ASSERT_EQ(read.rows(), expected.rows()) << what;
  for (const Column& c : expected.columns()) {
    const Column& r = read[c.name];
    for (std::size_t i = 0; i < c.values.size(); ++i) {
      EXPECT_TRUE(same_number(r.values[i], c.values[i]))
          << what << " column " << c.name << " row " << i << ": read " << r.values[i]
          << ", expected " << c.values[i];
    }
  }
}

class MotionAnalysisTest : public testing::TempDirTest {
 protected:
  TrajectoryReader stored(const Trajectories& run, const std::string& name = "run.h5") {
    write_trajectories(path(name), run);
    return TrajectoryReader(path(name));
  }
};

TEST_F(MotionAnalysisTest, DisplacementsTableHasOneRowPerGrainSeenInConsecutiveFrames) {
  const MotionAnalysis a = analyze_motion(stored(three_grain_run()), {});
  const Table& d = a.displacements;
  ASSERT_EQ(column_names(d),
            (std::vector<std::string>{"frame", "particle", "dx", "dy", "dz", "dr", "theta_axis_deg",
                                      "rot_disp", "theta_full_deg", "theta_body_x_deg",
                                      "theta_body_y_deg"}));
  EXPECT_EQ(d["dx"].unit, "mm");
  EXPECT_EQ(d["rot_disp"].unit, "mm");
  EXPECT_EQ(d["theta_axis_deg"].unit, "deg");
  EXPECT_TRUE(d["frame"].integer);
  EXPECT_TRUE(d["particle"].integer);
  EXPECT_EQ(a.length_unit, "mm");

  // Grain 20 is lost at 107: five rows, labelled by the later frame and by grain id.
  EXPECT_EQ(d["frame"].values, (std::vector<double>{105, 105, 105, 107, 107}));
  EXPECT_EQ(d["particle"].values, (std::vector<double>{10, 20, 30, 10, 30}));
  EXPECT_EQ(d["dx"].values, (std::vector<double>{3, 0, 1, 0, 2}));
  EXPECT_EQ(d["dy"].values, (std::vector<double>{4, 0, 2, 0, -1}));
  EXPECT_EQ(d["dz"].values, (std::vector<double>{0, 2, 2, -4, 2}));
  EXPECT_EQ(d["dr"].values, (std::vector<double>{5, 2, 3, 4, 3}));

  const std::vector<double> theta_axis{90, 0, 30, 0, 20};
  const std::vector<double> theta_full{90, 60, 30, 0, 20};
  const std::vector<double> radius{0.5, 1.0, 2.0, 0.5, 2.0};
  for (std::size_t r = 0; r < 5; ++r) {
    EXPECT_NEAR(d["theta_axis_deg"].values[r], theta_axis[r], 1e-12) << "row " << r;
    EXPECT_NEAR(d["theta_full_deg"].values[r], theta_full[r], 1e-12) << "row " << r;
    // Rotational displacement: the axis angle in radians times the grain's radius.
    EXPECT_NEAR(d["rot_disp"].values[r], theta_axis[r] * kDeg * radius[r], 1e-14) << "row " << r;
  }
}

TEST_F(MotionAnalysisTest, PerFrameStatisticsOfEachFramePair) {
  const MotionAnalysis a = analyze_motion(stored(three_grain_run()), {});
  const Table& p = a.per_frame;
  ASSERT_EQ(column_names(p),
            (std::vector<std::string>{"frame", "n", "mean_dr", "median_dr", "mean_theta_axis_deg",
                                      "mean_rot_disp", "median_theta_axis_deg", "median_rot_disp",
                                      "n_rot", "msd", "mean_theta_full_deg",
                                      "median_theta_full_deg", "drift_x", "drift_y", "drift_z",
                                      "prev_frame", "packing_fraction", "coordination"}));
  EXPECT_EQ(p["msd"].unit, "mm^2");
  EXPECT_EQ(p["frame"].values, (std::vector<double>{105, 107}));
  EXPECT_EQ(p["prev_frame"].values, (std::vector<double>{100, 105}));
  EXPECT_EQ(p["n"].values, (std::vector<double>{3, 2}));
  EXPECT_EQ(p["n_rot"].values, (std::vector<double>{3, 2}));

  // 105: dr = 5, 2, 3.  107: dr = 4, 3.
  EXPECT_EQ(p["mean_dr"].values, (std::vector<double>{10.0 / 3, 3.5}));
  EXPECT_EQ(p["median_dr"].values, (std::vector<double>{3, 3.5}));
  EXPECT_EQ(p["msd"].values, (std::vector<double>{38.0 / 3, 12.5}));
  // Drift: mean displacement, (4,6,4)/3 then (2,-1,-2)/2.
  EXPECT_EQ(p["drift_x"].values, (std::vector<double>{4.0 / 3, 1}));
  EXPECT_EQ(p["drift_y"].values, (std::vector<double>{2, -0.5}));
  EXPECT_EQ(p["drift_z"].values, (std::vector<double>{4.0 / 3, -1}));

  // 105: axis 90, 0, 30; rot_disp pi/4, 0, pi/3; full 90, 60, 30.
  // 107: axis 0, 20; rot_disp 0, 2 pi/9; full 0, 20.
  auto near = [&](const char* column, std::vector<double> expected) {
    for (std::size_t r = 0; r < expected.size(); ++r)
      EXPECT_NEAR(p[column].values[r], expected[r], 1e-12) << column << " row " << r;
  };
  near("mean_theta_axis_deg", {40, 10});
  near("median_theta_axis_deg", {30, 10});
  near("mean_rot_disp", {7 * M_PI / 36, M_PI / 9});
  near("median_rot_disp", {M_PI / 4, M_PI / 9});
  near("mean_theta_full_deg", {60, 10});
  near("median_theta_full_deg", {60, 10});
}

TEST_F(MotionAnalysisTest, DriftRemovalReachesTheTables) {
  AnalysisOptions options;
  options.motion.subtract_drift = true;
  const MotionAnalysis a = analyze_motion(stored(three_grain_run()), options);
  // The drift is still reported, and the residual displacements of each frame sum to 0.
  EXPECT_EQ(a.per_frame["drift_y"].values, (std::vector<double>{2, -0.5}));
  const Table& d = a.displacements;
  EXPECT_EQ(d["dx"].values, (std::vector<double>{3 - 4.0 / 3, -4.0 / 3, 1 - 4.0 / 3, -1, 1}));
  EXPECT_EQ(d["dy"].values, (std::vector<double>{2, -2, 0, 0.5, -0.5}));
  EXPECT_EQ(d["dr"].values[3], std::sqrt(1 + 0.25 + 9));
}

TEST_F(MotionAnalysisTest, HoleContactPolicyReachesTheTables) {
  Trajectories run = three_grain_run();
  run.header.has_hole_contact = true;
  for (Frame& f : run.frames)
    f.hole_contact = {0, 0, 0};
  run.frames[1].hole_contact[2] = 1;  // grain 30 locked at 105: both its pairs affected
  AnalysisOptions options;
  options.motion.hole_contacts = HoleContactPolicy::exclude_rotations;
  const MotionAnalysis a = analyze_motion(stored(run), options);
  EXPECT_EQ(a.per_frame["n"].values, (std::vector<double>{3, 2}));
  EXPECT_EQ(a.per_frame["n_rot"].values, (std::vector<double>{2, 1}));
  EXPECT_NEAR(a.per_frame["mean_theta_axis_deg"].values[0], 45, 1e-12);  // 90 and 0
  EXPECT_TRUE(std::isnan(a.displacements["theta_axis_deg"].values[2]));
  EXPECT_TRUE(std::isnan(a.displacements["theta_full_deg"].values[4]));
  EXPECT_EQ(a.displacements["dr"].values[4], 3.0);
}

TEST_F(MotionAnalysisTest, DefaultPdfsPoolEveryFrameAndIntegrateToOne) {
  const MotionAnalysis a = analyze_motion(stored(three_grain_run()), {});
  EXPECT_EQ(a.pdf_frames, (std::pair<std::int64_t, std::int64_t>{105, 107}));
  std::set<std::string> quantities;
  for (const auto& [q, pdf] : a.pdfs) {
    quantities.insert(q);
    EXPECT_EQ(pdf.rows(), 50u) << q;
    EXPECT_EQ(pdf_total_count(pdf), 5.0) << q;  // all five displacements
    EXPECT_NEAR(pdf_integral(pdf), 1.0, 1e-12) << q;
  }
  EXPECT_EQ(quantities, (std::set<std::string>{"dr", "theta_axis_deg", "rot_disp", "theta_full_deg",
                                               "theta_body_x_deg", "theta_body_y_deg"}));
  // The default range is that of the values: dr from 2 to 5.
  EXPECT_EQ(a.pdfs.at("dr")["bin_lo"].values.front(), 2.0);
  EXPECT_EQ(a.pdfs.at("dr")["bin_hi"].values.back(), 5.0);
  EXPECT_EQ(a.pdfs.at("dr")["density"].unit, "1/mm");
}

TEST_F(MotionAnalysisTest, PdfOfManyGrainsIntegratesToOne) {
  // A larger random run with a grain or two lost per frame.
  std::mt19937 rng(31);
  std::normal_distribution<double> gauss;
  Trajectories run;
  RunHeader& h = run.header;
  const Eigen::Index grains = 60;
  for (Eigen::Index i = 0; i < grains; ++i) {
    h.id.push_back(1000 + i);
    h.radius.push_back(1 + 0.01 * double(i));
  }
  h.has_axis = true;
  for (int t = 0; t < 4; ++t) {
    Frame f = Frame::unknown(h);
    f.step = t;
    for (Eigen::Index i = 0; i < grains; ++i) {
      f.position.row(i) << gauss(rng), gauss(rng), gauss(rng);
      f.axis.row(i) << gauss(rng), gauss(rng), gauss(rng);
    }
    f.position.row(t * 7).setConstant(kNaN);
    run.frames.push_back(f);
  }
  AnalysisOptions options;
  options.density.bins = 17;
  const MotionAnalysis a = analyze_motion(stored(run), options);
  // Frames 1, 2, 3: 58, 58, 58 grains seen in both (one lost in each of the two frames).
  EXPECT_EQ(a.per_frame["n"].values, (std::vector<double>{58, 58, 58}));
  EXPECT_EQ(a.pdfs.size(), 3u);  // dr, theta_axis_deg, rot_disp: no orientations
  for (const auto& [q, pdf] : a.pdfs) {
    EXPECT_EQ(pdf_total_count(pdf), 174.0) << q;
    EXPECT_NEAR(pdf_integral(pdf), 1.0, 1e-12) << q;
  }
  // The line angle never exceeds 90 degrees.
  EXPECT_LE(a.pdfs.at("theta_axis_deg")["bin_hi"].values.back(), 90.0);

  // With a range of [0, median) only half the values fall inside.
  const std::vector<double> dr = a.displacements["dr"].values;
  std::vector<double> sorted = dr;
  std::sort(sorted.begin(), sorted.end());
  options.pdf_quantities = {"dr"};
  options.density.range = std::make_pair(0.0, 0.5 * (sorted[86] + sorted[87]));
  const MotionAnalysis half = analyze_motion(TrajectoryReader(path("run.h5")), options);
  EXPECT_EQ(pdf_total_count(half.pdfs.at("dr")), 87.0);
  EXPECT_NEAR(pdf_integral(half.pdfs.at("dr")), 0.5, 1e-12);
}

TEST_F(MotionAnalysisTest, PdfWindowSelectsFramesByLabel) {
  const TrajectoryReader run = stored(three_grain_run());
  AnalysisOptions options;
  options.pdf_quantities = {"dr"};
  // Unit bins from 0 to 10: bin k counts the grains that moved k to k+1 mm.
  options.density.range = std::make_pair(0.0, 10.0);
  options.density.bins = 10;
  auto counts = [&](std::int64_t first, std::int64_t last) {
    options.pdf_frames = std::make_pair(first, last);
    const MotionAnalysis a = analyze_motion(run, options);
    EXPECT_EQ(a.pdf_frames, std::make_pair(first, last));
    EXPECT_EQ(a.pdfs.size(), 1u);
    return a.pdfs.at("dr")["count"].values;
  };
  using Counts = std::vector<double>;
  // 105 alone: dr 5, 2, 3.
  EXPECT_EQ(counts(105, 105), (Counts{0, 0, 1, 1, 0, 1, 0, 0, 0, 0}));
  EXPECT_EQ(counts(0, 105), (Counts{0, 0, 1, 1, 0, 1, 0, 0, 0, 0}));
  // 107 alone: dr 4, 3; labels between frames select nothing extra.
  EXPECT_EQ(counts(107, 107), (Counts{0, 0, 0, 1, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(counts(106, 1000), (Counts{0, 0, 0, 1, 1, 0, 0, 0, 0, 0}));
  // Both.
  EXPECT_EQ(counts(100, 107), (Counts{0, 0, 1, 2, 1, 1, 0, 0, 0, 0}));
  // The density is normalised by the values in the window, not in the run.
  options.pdf_frames = std::make_pair(107, 107);
  EXPECT_DOUBLE_EQ(analyze_motion(run, options).pdfs.at("dr")["density"].values[3], 0.5);
}

TEST_F(MotionAnalysisTest, PdfRequestsThatCannotBeMetAreErrors) {
  const TrajectoryReader run = stored(three_grain_run());
  AnalysisOptions options;
  // No displacement ends in 101..104 (frame 100 only starts one).
  options.pdf_frames = std::make_pair(101, 104);
  EXPECT_THROW(analyze_motion(run, options), Error);
  options.pdf_frames = std::make_pair(100, 100);
  EXPECT_THROW(analyze_motion(run, options), Error);
  options.pdf_frames = std::make_pair(107, 105);  // backwards: named as such
  EXPECT_NE(error_message([&] { analyze_motion(run, options); }).find("after last frame"),
            std::string::npos);

  options.pdf_frames.reset();
  for (const char* not_a_quantity : {"speed", "frame", "particle", "theta"}) {
    options.pdf_quantities = {"dr", not_a_quantity};
    EXPECT_THROW(analyze_motion(run, options), Error) << not_a_quantity;
  }
  options.pdf_quantities = {"dz"};  // any displacement column is a quantity
  EXPECT_EQ(pdf_total_count(analyze_motion(run, options).pdfs.at("dz")), 5.0);
}

// validate() alone: the defaults pass; each part's bad value is refused with its line,
// before any frame is read.
TEST(AnalysisOptions, ValidateNamesTheBadOptionAndPassesTheDefaults) {
  EXPECT_NO_THROW(AnalysisOptions{}.validate());
  AnalysisOptions window;
  window.pdf_frames = std::make_pair(7, 5);
  EXPECT_EQ(error_message([&] { window.validate(); }),
            "--window: first frame 7 is after last frame 5");
  window.pdf_frames = std::make_pair(5, 5);
  EXPECT_NO_THROW(window.validate());
  AnalysisOptions wall;
  wall.motion.wall_distance = -1;
  EXPECT_EQ(error_message([&] { wall.validate(); }), "--wall-distance: expected a length >= 0");
  AnalysisOptions bins;
  bins.density.bins = 0;
  EXPECT_EQ(error_message([&] { bins.validate(); }), "pdf: the number of bins must be at least 1");
}

TEST_F(MotionAnalysisTest, RunWithOneFrameHasNoDisplacements) {
  Trajectories run = three_grain_run();
  run.frames.resize(1);
  const TrajectoryReader one_frame = stored(run);
  // Refused up front, for the reason that there is no pair of frames.
  EXPECT_NE(error_message([&] { analyze_motion(one_frame, {}); }).find("at least two frames"),
            std::string::npos);
}

TEST_F(MotionAnalysisTest, TranslationOnlyRunHasNoRotationStatistics) {
  const TrajectoryReader run = stored(translation_only_run());
  const MotionAnalysis a = analyze_motion(run, {});
  // The columns are there (stable names), but nothing is measured.
  EXPECT_FALSE(a.displacements.has("theta_full_deg"));
  EXPECT_FALSE(a.per_frame.has("mean_theta_full_deg"));
  for (double v : a.displacements["theta_axis_deg"].values)
    EXPECT_TRUE(std::isnan(v));
  for (double v : a.displacements["rot_disp"].values)
    EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(a.per_frame["n_rot"].values, (std::vector<double>{0, 0}));
  EXPECT_TRUE(std::isnan(a.per_frame["mean_theta_axis_deg"].values[0]));
  // Translations are the same as with orientations.
  EXPECT_EQ(a.displacements["dr"].values, (std::vector<double>{5, 2, 3, 4, 3}));
  EXPECT_EQ(a.per_frame["msd"].values, (std::vector<double>{38.0 / 3, 12.5}));
  // Only dr by default; a rotation pdf has no measured values to work from.
  ASSERT_EQ(a.pdfs.size(), 1u);
  EXPECT_EQ(a.pdfs.begin()->first, "dr");
  AnalysisOptions rotation;
  rotation.pdf_quantities = {"theta_axis_deg"};
  EXPECT_THROW(analyze_motion(run, rotation), Error);
}

TEST_F(MotionAnalysisTest, TrackedAxesGiveSingleAxisRotationOnly) {
  // Axes from the orientations of the three-grain run: the same axis angles, no full ones.
  Trajectories run = three_grain_run();
  run.header.has_axis = true;
  run.header.has_orientation = false;
  for (Frame& f : run.frames) {
    f.axis.resize(3, 3);
    for (Eigen::Index i = 0; i < 3; ++i) {
      const Eigen::Quaterniond q(f.orientation(i, 0), f.orientation(i, 1), f.orientation(i, 2),
                                 f.orientation(i, 3));
      // Stored with an arbitrary sign, as a tracker would: a line has no direction.
      f.axis.row(i) = (i % 2 ? -1.0 : 1.0) * (q * Eigen::Vector3d::UnitZ()).transpose();
    }
    f.orientation.resize(0, 4);
  }
  const MotionAnalysis a = analyze_motion(stored(run), {});
  EXPECT_FALSE(a.displacements.has("theta_full_deg"));
  const std::vector<double> theta_axis{90, 0, 30, 0, 20};
  for (std::size_t r = 0; r < 5; ++r)
    EXPECT_NEAR(a.displacements["theta_axis_deg"].values[r], theta_axis[r], 1e-12) << r;
  EXPECT_EQ(a.pdfs.size(), 3u);
}

TEST_F(MotionAnalysisTest, WrittenTablesReadBackExactly) {
  const MotionAnalysis a = analyze_motion(stored(three_grain_run()), {});
  const fs::path out = path("analysis/nested");  // created on demand
  const std::vector<fs::path> written =
      write_motion_analysis(a, out, {"granmem analyze run.h5"}, {{"pdf_bins", "50"}});

  std::set<std::string> names;
  for (const fs::path& p : written) {
    EXPECT_EQ(p.parent_path(), out);
    names.insert(p.filename().string());
  }
  const std::set<std::string> expected_names{"displacements.csv",
                                             "per_frame.csv",
                                             "pdf_dr.csv",
                                             "pdf_theta_axis_deg.csv",
                                             "pdf_rot_disp.csv",
                                             "pdf_theta_full_deg.csv",
                                             "pdf_theta_body_x_deg.csv",
                                             "pdf_theta_body_y_deg.csv",
                                             "analysis.h5"};
  EXPECT_EQ(names, expected_names);
  // Nothing else is left in the folder: no temporary files.
  std::set<std::string> present;
  for (const auto& entry : fs::directory_iterator(out))
    present.insert(entry.path().filename().string());
  EXPECT_EQ(present, expected_names);

  // CSVs: the comment lines first, then the numbers, each reading back to the same double.
  const std::string text = read_text(out / "displacements.csv");
  EXPECT_EQ(text.rfind("# granmem analyze run.h5\n", 0), 0u);
  // A pdf says which frames it pools.
  EXPECT_NE(read_text(out / "pdf_dr.csv").find("over frames 105 to 107"), std::string::npos);
  auto csv = [&](const std::string& file, const Table& table) {
    expect_same_values(read_csv(out / file, column_names(table)).table, table, file);
  };
  csv("displacements.csv", a.displacements);
  csv("per_frame.csv", a.per_frame);
  for (const auto& [q, pdf] : a.pdfs)
    csv("pdf_" + q + ".csv", pdf);

  // HDF5: the same tables, with units and integer columns, the window and the parameters.
  const h5::File f = h5::File::open(out / "analysis.h5");
  const Table d = h5::read_table(f, "/displacements");
  expect_same_values(d, a.displacements, "/displacements");
  EXPECT_EQ(d["dr"].unit, "mm");
  EXPECT_TRUE(d["particle"].integer);
  expect_same_values(h5::read_table(f, "/per_frame"), a.per_frame, "/per_frame");
  for (const auto& [q, pdf] : a.pdfs) {
    expect_same_values(h5::read_table(f, "/pdf/" + q), pdf, "/pdf/" + q);
    const h5::Handle g = h5::open_group(f, "/pdf/" + q);
    EXPECT_EQ(h5::read_string_attribute(g.get(), "frames"), "frames 105 to 107");
  }
  const h5::Handle params = h5::open_group(f, "/parameters/analyze");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "pdf_bins"), "50");
}

TEST_F(MotionAnalysisTest, UnmeasuredValuesAreWrittenAsNaN) {
  const MotionAnalysis a = analyze_motion(stored(translation_only_run()), {});
  const fs::path out = path("out");
  write_motion_analysis(a, out, {}, {});
  const Table read = read_csv(out / "displacements.csv", column_names(a.displacements)).table;
  expect_same_values(read, a.displacements, "displacements.csv");
  EXPECT_TRUE(std::isnan(read["theta_axis_deg"].values[0]));
  // The theta columns are NaN and dr is finite, so this is not vacuous.
  EXPECT_EQ(read["dr"].values[0], 5.0);
  EXPECT_NE(read_text(out / "displacements.csv").find(",nan,nan"), std::string::npos);
}

}  // namespace
}  // namespace granmem

namespace granmem {
namespace {

TEST_F(MotionAnalysisTest, DefaultPdfWithoutMeasuredValuesIsSkippedWithANote) {
  // Orientations all unknown: rotations are columns of the run but never measured.
  Trajectories run = three_grain_run();
  for (Frame& f : run.frames)
    f.orientation.setConstant(kNaN);
  const MotionAnalysis a = analyze_motion(stored(run), {});
  EXPECT_EQ(a.pdfs.size(), 1u);  // dr only
  EXPECT_EQ(a.pdfs.count("dr"), 1u);
  ASSERT_EQ(a.notes.size(), 5u);  // theta_axis_deg, rot_disp, theta_full_deg, theta_body_x/y
  EXPECT_NE(a.notes[0].find("no pdf of theta_axis_deg"), std::string::npos);
  // Asked for by name, the same pdf is an error.
  AnalysisOptions asked;
  asked.pdf_quantities = {"theta_axis_deg"};
  EXPECT_THROW(analyze_motion(stored(run, "again.h5"), asked), Error);
}

TEST_F(MotionAnalysisTest, NoGrainFollowedGivesTablesButNoPdfs) {
  // Every grain lost in the middle frame: no displacement anywhere.
  Trajectories run = three_grain_run();
  run.frames[1].position.setConstant(kNaN);
  const MotionAnalysis a = analyze_motion(stored(run), {});
  EXPECT_EQ(a.displacements.rows(), 0u);
  EXPECT_EQ(a.per_frame["n"].values, (std::vector<double>{0, 0}));
  EXPECT_TRUE(a.pdfs.empty());
  ASSERT_EQ(a.notes.size(), 1u);
}

}  // namespace
}  // namespace granmem

namespace granmem {
namespace {

// analyze as one call: the tables written, the report's counts and rows, and a note where
// rotations cannot become lengths (no radius).
TEST_F(MotionAnalysisTest, AnalyzeRunWritesTheTablesAndReportsTheRun) {
  const AnalyzeSummary s = analyze_run(stored(three_grain_run()), {}, path("out"), {});
  EXPECT_TRUE(fs::exists(path("out") / "displacements.csv"));
  EXPECT_TRUE(fs::exists(path("out") / "analysis.h5"));
  EXPECT_EQ(std::count(s.written.begin(), s.written.end(), path("out") / "per_frame.csv"), 1);
  const std::string report = s.Report();
  // Grain 20 is not seen in frame 107: 3 + 2 displacements. Frame 105: dr 5, 2, 3 and axis
  // turns 90, 0, 30 degrees; frame 107: dr 4, 3 and turns 0, 20.
  EXPECT_EQ(
      report.rfind(
          path("run.h5").string() + ": 5 displacements over 2 frame pairs, lengths in mm\n", 0),
      0u)
      << report;
  EXPECT_NE(report.find("\n    105       3        3.3333             3            40\n"
                        "    107       2           3.5           3.5            10\n"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("wrote " + (path("out") / "analysis.h5").string()), std::string::npos);
  EXPECT_TRUE(std::none_of(s.notes.begin(), s.notes.end(), [](const std::string& n) {
    return n.find("no grain radius") != std::string::npos;
  }));

  Trajectories no_radius = three_grain_run();
  no_radius.header.radius.assign(3, std::numeric_limits<double>::quiet_NaN());
  const AnalyzeSummary t = analyze_run(stored(no_radius, "bare.h5"), {}, path("bare"), {});
  EXPECT_TRUE(std::any_of(t.notes.begin(), t.notes.end(), [](const std::string& n) {
    return n.find("bare.h5 has no grain radius, so rot_disp is nan") != std::string::npos;
  }));
}

}  // namespace
}  // namespace granmem
