// End to end: `granmem link` on detections written as a user's files would be (HDF5 and
// CSV), checked against the known grains; its report, its TOML section, `granmem analyze`
// on the result, and bad input.

#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "granmem/core/hdf5.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;

// 6 x 6 x 6 grains of diameter 1 mm on a cubic lattice of spacing 1 mm, drifting by
// (0.6, 0, -0.3) mm per scan and moving randomly by up to 0.15 mm per axis. Grain 7 is
// missing from scan 1; scan 2 has one more detection, far out.
class LinkCommandTest : public GranmemTest {
 protected:
  static constexpr int kSide = 6, kGrains = kSide * kSide * kSide;

  void SetUp() override {
    GranmemTest::SetUp();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> wobble(-0.15, 0.15);
    truth_.assign(3, std::vector<Eigen::Vector3d>(kGrains));
    for (int g = 0; g < kGrains; ++g)
      truth_[0][std::size_t(g)] = Eigen::Vector3d(g % kSide, g / kSide % kSide, g / kSide / kSide);
    for (std::size_t t = 1; t < 3; ++t) {
      for (std::size_t g = 0; g < kGrains; ++g)
        truth_[t][g] = truth_[t - 1][g] + Eigen::Vector3d(0.6, 0, -0.3) +
                       Eigen::Vector3d(wobble(rng), wobble(rng), wobble(rng));
    }
    // Detections in reverse grain order, so that detection index and grain differ.
    for (std::size_t t = 0; t < 3; ++t) {
      for (int g = kGrains - 1; g >= 0; --g) {
        if (t == 1 && g == 7) continue;
        grain_[t].push_back(g);
        seen_[t].push_back(truth_[t][std::size_t(g)]);
      }
    }
    grain_[2].push_back(-1);
    seen_[2].push_back(Eigen::Vector3d(30, 30, 30));
    write_h5(in_work("scan0.h5"), 0, seen_[0], "mm");
    write_csv_scan(in_work("scan1.csv"), 1, seen_[1], "mm");
    write_csv_scan(in_work("scan2.csv"), 2, seen_[2], "mm");
  }

  static void write_csv_scan(const fs::path& path, int frame, const std::vector<Eigen::Vector3d>& p,
                             const std::string& unit) {
    std::ostringstream s;
    s.precision(17);
    s << "# granmem detections of stack, frame " << frame << ", lengths in " << unit << "\n"
      << "frame,particle,x,y,z,radius,quality,edge\n";
    for (std::size_t k = 0; k < p.size(); ++k)
      s << frame << "," << k << "," << p[k][0] << "," << p[k][1] << "," << p[k][2] << ",0.5,1,0\n";
    write_text(path, s.str());
  }

  static void write_h5(const fs::path& path, int frame, const std::vector<Eigen::Vector3d>& p,
                       const std::string& unit) {
    Table t;
    Column& f = t.add("frame", "", true);
    Column& particle = t.add("particle", "", true);
    Column* x[3] = {&t.add("x", unit), &t.add("y", unit), &t.add("z", unit)};
    Column& radius = t.add("radius", unit);
    Column& quality = t.add("quality");
    Column& edge = t.add("edge", "", true);
    for (std::size_t k = 0; k < p.size(); ++k) {
      f.values.push_back(frame);
      particle.values.push_back(double(k));
      for (int a = 0; a < 3; ++a)
        x[a]->values.push_back(p[k][a]);
      radius.values.push_back(0.5);
      quality.values.push_back(1);
      edge.values.push_back(0);
    }
    h5::File file = h5::File::create(path);
    h5::write_table(file.id(), "/detections", t);
    h5::Handle g = h5::open_group(file, "/detections");
    h5::write_attribute(g.get(), "length_unit", unit);
    h5::write_attribute(g.get(), "source", "stack0.tif");
    h5::write_attribute(g.get(), "frame", std::to_string(frame));
    file.close();
  }

  // Each track must follow one grain: the grain whose detection it has in every scan.
  void expect_true_tracks(const Trajectories& run, std::size_t expected_tracks) {
    ASSERT_EQ(run.frames.size(), 3u);
    ASSERT_EQ(run.header.grain_count(), expected_tracks);
    std::size_t full = 0;
    for (std::size_t k = 0; k < run.header.grain_count(); ++k) {
      std::int64_t grain = -2;
      bool all = true;
      for (std::size_t t = 0; t < 3; ++t) {
        const Eigen::Vector3d p = run.frames[t].position.row(Eigen::Index(k)).transpose();
        if (!p.allFinite()) {
          all = false;
          continue;
        }
        std::int64_t g = -3;
        for (std::size_t j = 0; j < seen_[t].size(); ++j)
          if (seen_[t][j] == p) g = grain_[t][j];
        ASSERT_NE(g, -3) << "track " << k << " frame " << t << ": not a detection";
        if (grain == -2) grain = g;
        EXPECT_EQ(g, grain) << "track " << k << " joins two grains";
      }
      full += all;
    }
    EXPECT_EQ(full, std::size_t(kGrains) - 1);  // all but grain 7
  }

  std::vector<std::vector<Eigen::Vector3d>> truth_;
  std::vector<Eigen::Vector3d> seen_[3];
  std::vector<std::int64_t> grain_[3];
};

TEST_F(LinkCommandTest, LinksReportsAndAnalyzes) {
  const RunResult r = granmem_ok({"link", "scan0.h5", "scan1.csv", "scan2.csv", "--out",
                                  "tracks.h5", "--report", "unlinked.csv"});
  EXPECT_NE(r.out.find("linked 3 scans: 217 tracks, max displacement 0.7 mm"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("99.54%"), std::string::npos) << r.out;  // 215 of 216 in scan 1
  EXPECT_EQ(r.err, "");
  ASSERT_TRUE(fs::exists(in_work("tracks.xmf")));

  const Trajectories run = read_trajectories(in_work("tracks.h5"));
  // The grain missing in scan 1 rejoins its track (memory); the extra detection starts one.
  expect_true_tracks(run, kGrains + 1);
  EXPECT_EQ(run.header.length_unit, "mm");
  EXPECT_EQ(run.frames[2].step, 2);
  EXPECT_EQ(run.header.parameters.at("link/memory"), "2");
  EXPECT_EQ(run.header.parameters.at("link/max-displacement"), "auto");
  EXPECT_EQ(run.header.parameters.at("link/max_displacement"), "0.7 mm");
  EXPECT_EQ(run.header.parameters.at("link/drift"), "on");

  // The report: grain 7 lost in frame 1 (its track is the one of detection 215 - 7 = 208 of
  // scan 0, tracks numbered by first detection), the far detection new in frame 2.
  const Table report = read_columns(in_work("unlinked.csv"),
                                    {"frame", "particle", "detection", "lost", "x", "y", "z"});
  ASSERT_EQ(report.rows(), 2u);
  EXPECT_EQ(report["frame"].values, (std::vector<double>{1, 2}));
  EXPECT_EQ(report["lost"].values, (std::vector<double>{1, 0}));
  EXPECT_EQ(report["particle"].values, (std::vector<double>{208, 216}));
  EXPECT_EQ(report["detection"].values, (std::vector<double>{-1, 216}));
  EXPECT_EQ(report["x"].values[0], truth_[0][7][0]);
  EXPECT_EQ(report["z"].values[1], 30);

  const RunResult a = granmem_ok({"analyze", "tracks.h5", "--out", "analysis"});
  EXPECT_NE(a.out.find("2 frame pairs"), std::string::npos) << a.out;
  EXPECT_TRUE(fs::exists(in_work("analysis")));
}

TEST_F(LinkCommandTest, TheApparatusReadingsAreStoredWithTheTracks) {
  write_text(in_work("readings.csv"),
             "cycle,wall_force_full_compression,wall_force_unloaded\n1,12.5,3\n2,12.25,3.5\n");
  const RunResult r = granmem_ok({"link", "scan0.h5", "scan1.csv", "scan2.csv", "--out",
                                  "tracks.h5", "--readings", "readings.csv"});
  EXPECT_NE(r.err.find("the wall's force at full compression at 2 cycles, unloaded at 2 cycles"),
            std::string::npos)
      << r.err;
  // Under the names a simulation's store gives them, which calibrate compares.
  const Trajectories run = read_trajectories(in_work("tracks.h5"));
  EXPECT_EQ(run.observables.at("wall_force_full_compression").value,
            (std::vector<double>{12.5, 12.25}));
  EXPECT_EQ(run.observables.at("wall_force").value, (std::vector<double>{3, 3.5}));
  EXPECT_EQ(run.observables.at("wall_force").step, (std::vector<std::int64_t>{1, 2}));
}

TEST_F(LinkCommandTest, ConfigSection) {
  // [link] in a TOML file: no memory, so the missing grain starts a second track.
  write_text(in_work("granmem.toml"), "[link]\nmemory = 0\nmax-displacement = \"0.45 mm\"\n");
  const RunResult r = granmem_ok(
      {"--config", "granmem.toml", "link", "scan0.h5", "scan1.csv", "scan2.csv", "-o", "t.h5"});
  const Trajectories run = read_trajectories(in_work("t.h5"));
  expect_true_tracks(run, kGrains + 2);
  EXPECT_EQ(run.header.parameters.at("link/memory"), "0");
  EXPECT_EQ(run.header.parameters.at("link/max_displacement"), "0.45 mm");
}

TEST_F(LinkCommandTest, NoDriftLosesTheGrains) {
  // The drift (0.67 mm) is beyond a max displacement of 0.4 mm: with its estimate every
  // grain is found again, without it most are not.
  granmem_ok({"link", "scan0.h5", "scan1.csv", "--out", "drift.h5", "--max-displacement", "0.4"});
  EXPECT_EQ(read_trajectories(in_work("drift.h5")).header.grain_count(), std::size_t(kGrains));
  granmem_ok({"link", "scan0.h5", "scan1.csv", "--out", "t.h5", "--no-collective-motion",
              "--max-displacement", "400um"});
  const Trajectories run = read_trajectories(in_work("t.h5"));
  EXPECT_GT(run.header.grain_count(), std::size_t(kGrains + 150));
  EXPECT_EQ(run.header.parameters.at("link/drift"), "off");
  EXPECT_EQ(run.header.parameters.at("link/max_displacement"), "0.4 mm");
}

// The container given in the scans' frame (in cm, the scans in mm): positions stored from
// its lower corner, and it is the store's box, so a scan's fields share the DEM's frame.
TEST_F(LinkCommandTest, PositionsAreStoredInTheContainersFrame) {
  granmem_ok({"link", "scan0.h5", "scan1.csv", "--out", "plain.h5"});
  granmem_ok({"link", "scan0.h5", "scan1.csv", "--out", "boxed.h5", "--container",
              "-0.1,0.2,0.3,4.9,5.2,7.3cm"});
  const Trajectories plain = read_trajectories(in_work("plain.h5"));
  const Trajectories boxed = read_trajectories(in_work("boxed.h5"));
  ASSERT_TRUE(boxed.header.box.has_value());
  EXPECT_TRUE(boxed.header.box->lower.isZero());
  EXPECT_TRUE(boxed.header.box->edges.isApprox(Eigen::Vector3d(50, 50, 70)));
  for (std::size_t t = 0; t < plain.frames.size(); ++t) {
    const Eigen::MatrixXd shift = plain.frames[t].position - boxed.frames[t].position;
    for (Eigen::Index k = 0; k < shift.rows(); ++k) {
      if (!shift.row(k).allFinite()) continue;
      EXPECT_TRUE(shift.row(k).isApprox(Eigen::RowVector3d(-1, 2, 3), 1e-9)) << shift.row(k);
    }
  }
  // Found from the packing's extent: across x and y the surfaces' extent in the first scan
  // centred in the container, along z the bottom layer (exact here) on its floor.
  granmem_ok({"link", "scan0.h5", "scan1.csv", "--out", "found.h5", "--container-size", "5,5,7cm"});
  const Trajectories found = read_trajectories(in_work("found.h5"));
  ASSERT_TRUE(found.header.box.has_value());
  EXPECT_TRUE(found.header.box->edges.isApprox(Eigen::Vector3d(50, 50, 70)));
  Eigen::Vector3d lowest = Eigen::Vector3d::Constant(1e9), highest = -lowest;
  for (Eigen::Index k = 0; k < found.frames[0].position.rows(); ++k) {
    const double r = found.header.radius[std::size_t(k)];
    if (!found.frames[0].position.row(k).allFinite() || !std::isfinite(r)) continue;
    lowest =
        lowest.cwiseMin(found.frames[0].position.row(k).transpose() - Eigen::Vector3d::Constant(r));
    highest = highest.cwiseMax(found.frames[0].position.row(k).transpose() +
                               Eigen::Vector3d::Constant(r));
  }
  EXPECT_NEAR(lowest.x() + highest.x(), 50, 1e-9);
  EXPECT_NEAR(lowest.y() + highest.y(), 50, 1e-9);
  EXPECT_NEAR(lowest.z(), 0, 1e-9);
  expect_clean_failure({"link", "scan0.h5", "scan1.csv", "--out", "x.h5", "--container-size",
                        "5,5,7cm", "--container", "0,0,0,5,5,7cm"},
                       {"not both"});
  expect_clean_failure(
      {"link", "scan0.h5", "scan1.csv", "--out", "x.h5", "--container", "0,0,0,5,5,7"},
      {"--container", "length unit"});
  expect_clean_failure(
      {"link", "scan0.h5", "scan1.csv", "--out", "x.h5", "--container", "0,0,0,5,-5,7cm"},
      {"--container", "greater than its min"});
}

using LinkBadInputTest = LinkCommandTest;

TEST_F(LinkBadInputTest, Errors) {
  expect_clean_failure({"link", "--out", "t.h5"}, {"scans"});
  expect_clean_failure({"link", "nothere.h5", "--out", "t.h5"}, {"nothere.h5"});
  write_text(in_work("garbage.h5"), "not an hdf5 file");
  expect_clean_failure({"link", "scan0.h5", "garbage.h5", "--out", "t.h5"}, {"garbage.h5"});
  write_csv_scan(in_work("voxels.csv"), 1, seen_[1], "voxel");
  expect_clean_failure({"link", "scan0.h5", "voxels.csv", "--out", "t.h5"},
                       {"voxels.csv: lengths in voxel, but scan0.h5 in mm"});
  expect_clean_failure({"link", "scan1.csv", "scan0.h5", "--out", "t.h5"}, {"not after frame 1"});
  expect_clean_failure({"link", "scan0.h5", "scan1.csv", "--out", "t.h5", "--memory", "-1"},
                       {"memory"});
  expect_clean_failure(
      {"link", "scan0.h5", "scan1.csv", "--out", "t.h5", "--max-displacement", "2 parsecs"},
      {"--max-displacement"});
  write_text(in_work("readings.csv"), "cycle,lid_height\n1,0.05\n");
  expect_clean_failure(
      {"link", "scan0.h5", "scan1.csv", "--out", "t.h5", "--readings", "readings.csv"},
      {"readings.csv", "no column wall_force_full_compression"});
  // An existing result is left as it was.
  write_text(in_work("t.h5"), "keep me");
  expect_clean_failure({"link", "scan0.h5", "voxels.csv", "--out", "t.h5"}, {"one length unit"});
}

}  // namespace
}  // namespace granmem::testing
