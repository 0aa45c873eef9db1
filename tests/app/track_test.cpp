// `granmem locate` and `granmem track` on the sample scans (a simulated packing rendered
// with every artefact, its truth beside it): grains found, where, linked to themselves;
// and bad input stopping cleanly.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/single_axis_rotation.hpp"
#include "granmem/tracking/detections.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

const std::filesystem::path kScans = std::filesystem::path(GRANMEM_SAMPLE_DATA) / "scans";
// The sample scans' voxel (m): 5 mm grains drawn 12 px across, slices 1.5 px apart.
const Eigen::Vector3d kVoxel(5e-3 / 12, 5e-3 / 12, 1.5 * 5e-3 / 12);

struct Truth {
  std::vector<double> id;
  std::vector<Eigen::Vector3d> voxel;  // positions in voxels
  std::vector<Eigen::Vector3d> axis;   // hole axes
};

Truth read_truth(int scan) {
  const Table t = read_csv(kScans / ("truth" + std::to_string(scan) + ".csv"),
                           {"particle", "x", "y", "z", "ax", "ay", "az"})
                      .table;
  Truth truth;
  for (std::size_t i = 0; i < t.rows(); ++i) {
    truth.id.push_back(t["particle"].values[i]);
    truth.voxel.emplace_back(t["x"].values[i], t["y"].values[i], t["z"].values[i]);
    truth.axis.emplace_back(t["ax"].values[i], t["ay"].values[i], t["az"].values[i]);
  }
  return truth;
}

// For each true grain, the nearest of `found` (voxels) within a quarter diameter, or -1.
std::vector<long> match(const Truth& truth, const std::vector<Eigen::Vector3d>& found) {
  std::vector<long> nearest;
  for (const Eigen::Vector3d& t : truth.voxel) {
    long best = -1;
    double best_distance = 3;  // voxels: a quarter of the 12-voxel diameter
    for (std::size_t k = 0; k < found.size(); ++k) {
      const double d = (found[k] - t).norm();
      if (d < best_distance) best_distance = d, best = long(k);
    }
    nearest.push_back(best);
  }
  return nearest;
}

// Checks one scan's grains: nearly all found, none made up, within a tenth of a voxel.
void expect_found(const Truth& truth, const std::vector<Eigen::Vector3d>& found,
                  const std::string& what) {
  const std::vector<long> m = match(truth, found);
  std::size_t hits = 0;
  Eigen::Array3d squared = Eigen::Array3d::Zero();
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (m[i] < 0) continue;
    ++hits;
    squared += (found[std::size_t(m[i])] - truth.voxel[i]).array().square();
  }
  EXPECT_GE(double(hits), 0.995 * double(truth.voxel.size())) << what;
  EXPECT_LE(double(found.size() - hits), 0.005 * double(truth.voxel.size())) << what;
  const Eigen::Array3d rms = (squared / double(std::max<std::size_t>(hits, 1))).sqrt();
  EXPECT_LT(rms.maxCoeff(), 0.1) << what << ": rms " << rms.transpose() << " voxel";
}

using TrackTest = GranmemTest;

TEST_F(TrackTest, LocatesEveryGrainOfAScanToAFractionOfAVoxel) {
  const RunResult r = granmem_ok({"locate", (kScans / "scan0.tif").string(), "--diameter", "5mm",
                                  "--out", "d.h5", "--csv", "d.csv"});
  EXPECT_NE(r.out.find("lengths in m"), std::string::npos) << r.out;
  const Detections d = read_detections(in_work("d.h5"));
  ASSERT_TRUE(d.voxel_size);
  EXPECT_NEAR((*d.voxel_size - kVoxel).norm(), 0, 1e-9);  // from the TIFF's ImageJ metadata
  std::vector<Eigen::Vector3d> voxels;
  std::vector<double> radii;
  for (std::size_t k = 0; k < d.size(); ++k) {
    voxels.push_back(Eigen::Vector3d(d.position.row(Eigen::Index(k))).cwiseQuotient(kVoxel));
    radii.push_back(d.radius[k]);
  }
  expect_found(read_truth(0), voxels, "scan0");
  // The fitted radius runs some 6% small on these scans (slices 1.5x coarser and blurred
  // more along z than the one-blur model has): a known bias of the radius, not the centre.
  std::nth_element(radii.begin(), radii.begin() + long(radii.size() / 2), radii.end());
  EXPECT_NEAR(radii[radii.size() / 2], 2.5e-3, 0.08 * 2.5e-3);
  EXPECT_EQ(csv_header(in_work("d.csv")).rfind("frame,particle,x,y,z,radius,quality,edge", 0), 0u);
}

TEST_F(TrackTest, RegionKeepsTheWholeStacksCoordinates) {
  // The box from voxel (20,20,20) on: the grains inside it where the whole scan has them.
  granmem_ok({"locate", (kScans / "scan0.tif").string(), "-d", "12", "--region", "20,20,20,0,0,0",
              "--out", "r.h5"});
  const Detections d = read_detections(in_work("r.h5"));
  const Truth truth = read_truth(0);
  std::size_t inside = 0, checked = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    if (d.edge[k]) continue;
    const Eigen::Vector3d p =
        Eigen::Vector3d(d.position.row(Eigen::Index(k))).cwiseQuotient(kVoxel);
    EXPECT_TRUE((p.array() > 20).all()) << p.transpose();
    // Grains whose blurred image the box cuts are located less well: those clear of it.
    if (((p.array() - 20) < Eigen::Array3d(7, 7, 5)).any()) continue;
    double nearest = 1e9;
    for (const Eigen::Vector3d& t : truth.voxel)
      nearest = std::min(nearest, (t - p).norm());
    EXPECT_LT(nearest, 0.3) << p.transpose();
    ++checked;
  }
  for (const Eigen::Vector3d& t : truth.voxel)
    inside += ((t.array() - 20) >= Eigen::Array3d(7.5, 7.5, 5.5)).all();
  EXPECT_GE(checked, inside - 1);  // all of those found (one may sit right at the limit)
}

TEST_F(TrackTest, TracksTheScansIntoTrajectoriesThatAnalyzeReads) {
  const RunResult r =
      granmem_ok({"track", (kScans / "scan2.tif").string(), (kScans / "scan0.tif").string(),
                  (kScans / "scan1.tif").string(), "-d", "12", "--out", "tracks.h5", "--detections",
                  "det", "--analyze", "analysis"});
  // Scans are taken in natural order whatever the order given.
  EXPECT_LT(r.out.find("scan0.tif"), r.out.find("scan1.tif")) << r.out;
  EXPECT_LT(r.out.find("scan1.tif"), r.out.find("scan2.tif")) << r.out;
  EXPECT_TRUE(std::filesystem::exists(in_work("det/scan1.h5")));

  const TrajectoryReader store(in_work("tracks.h5"));
  ASSERT_EQ(store.frame_count(), 3u);
  EXPECT_EQ(store.header().length_unit, "m");
  std::vector<Truth> truth;
  std::vector<std::vector<long>> matched;  // per scan: true grain -> track row
  for (int s = 0; s < 3; ++s) {
    truth.push_back(read_truth(s));
    const Frame f = store.read_frame(std::size_t(s));
    std::vector<Eigen::Vector3d> voxels;
    for (Eigen::Index k = 0; k < f.position.rows(); ++k) {
      const Eigen::Vector3d p = f.position.row(k);
      voxels.push_back(p.allFinite() ? Eigen::Vector3d(p.cwiseQuotient(kVoxel))
                                     : Eigen::Vector3d::Constant(-1e9));
    }
    expect_found(truth.back(), voxels, "frame " + std::to_string(s));
    matched.push_back(match(truth.back(), voxels));
  }
  // Each true grain keeps its track from scan to scan.
  for (int s = 1; s < 3; ++s) {
    std::size_t same = 0, both = 0;
    for (std::size_t i = 0; i < truth[0].id.size(); ++i) {
      ASSERT_EQ(truth[std::size_t(s)].id[i], truth[0].id[i]);
      if (matched[0][i] < 0 || matched[std::size_t(s)][i] < 0) continue;
      ++both;
      same += matched[0][i] == matched[std::size_t(s)][i];
    }
    EXPECT_EQ(same, both) << "scan " << s;
  }
  // One command from scans to rotation statistics: the analysis, grains touching a
  // neighbour through their hole left out of the rotations (their hole locks on it).
  EXPECT_TRUE(std::filesystem::exists(in_work("analysis/analysis.h5")));
  EXPECT_NE(r.out.find("displacements.csv"), std::string::npos) << r.out;

  // The single-axis rotations measured against the true ones, grain by grain (issue 5's
  // bar: median error <= 1 deg, 95 % <= 3 deg).
  std::map<double, std::size_t> truth_of_track;  // track id -> true grain
  for (std::size_t i = 0; i < truth[0].id.size(); ++i) {
    if (matched[0][i] >= 0)
      truth_of_track[double(store.header().id[std::size_t(matched[0][i])])] = i;
  }
  const Table d =
      read_csv(in_work("analysis/displacements.csv"), {"frame", "particle", "theta_axis_deg"})
          .table;
  std::vector<double> error;
  for (std::size_t r = 0; r < d.rows(); ++r) {
    const double measured = d["theta_axis_deg"].values[r];
    const auto it = truth_of_track.find(d["particle"].values[r]);
    if (!std::isfinite(measured) || it == truth_of_track.end()) continue;
    const auto scan = std::size_t(std::lround(d["frame"].values[r]));  // labels 0, 1, 2
    ASSERT_GE(scan, 1u);
    ASSERT_LE(scan, 2u);
    const double truth_deg =
        single_axis_angle(truth[scan - 1].axis[it->second], truth[scan].axis[it->second]) * 180 /
        M_PI;
    error.push_back(std::abs(measured - truth_deg));
  }
  // A grain flagged in either scan of a pair has no rotation: ~a quarter in each.
  ASSERT_GE(double(error.size()), 0.4 * 2 * double(truth[0].id.size()));
  std::sort(error.begin(), error.end());
  const double median = error[error.size() / 2], p95 = error[error.size() * 95 / 100];
  std::cout << "single-axis rotation error: median " << median << " deg, 95 % " << p95
            << " deg over " << error.size() << " grain-steps\n";
  EXPECT_LT(median, 1.0);
  EXPECT_LT(p95, 3.0);
}

TEST_F(TrackTest, BadScansStopWithOneLineAndWriteNothing) {
  // A TIFF cut in half.
  const std::string whole = read_file(kScans / "scan0.tif");
  {
    std::ofstream f(in_work("cut.tif"), std::ios::binary);
    f.write(whole.data(), std::streamsize(whole.size() / 2));
  }
  write_text(in_work("d.h5"), "keep me");
  expect_clean_failure({"locate", "cut.tif", "-d", "12", "--out", "d.h5"}, {"cut.tif"});
  expect_clean_failure({"locate", (kScans / "scan0.tif").string(), "-d", "200", "--out", "d.h5"},
                       {"larger than the stack"});
  expect_clean_failure({"locate", (kScans / "scan0.tif").string(), "-d", "12mm", "--out", "d.h5",
                        "--voxel-size", "0.1,0.1"},
                       {"--voxel-size"});
  expect_clean_failure({"locate", "missing.tif", "-d", "12", "--out", "d.h5"}, {"missing.tif"});
  // A bad scan after a good one: the good one was located (and said so), nothing written.
  const auto before = snapshot(work());
  const RunResult r =
      granmem({"track", (kScans / "scan0.tif").string(), "cut.tif", "-d", "12", "--out", "d.h5"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("granmem: error: ", 0), 0u) << r.err;
  EXPECT_EQ(snapshot(work()), before);
}

}  // namespace
}  // namespace granmem::testing
