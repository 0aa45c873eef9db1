// `granmem render`: a frame of a run drawn as a TIFF stack, with its truth table; options
// from the command line and from a [render] section of --config; bad input stops cleanly.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "granmem/tracking/stack.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Four grains of radius 1 mm, 3 mm or more apart; frame 1 moves them by fractions of a voxel.
const char* kRun =
    "frame,particle,x,y,z,radius\n"
    "0,11,2,2,2,1\n0,12,5,2,2,1\n0,13,2,5,2.5,1\n0,14,5,5,5,1\n"
    "1,11,2.03,2.11,2.07,1\n1,12,5.17,2.04,2.13,1\n1,13,2.09,5.12,2.61,1\n1,14,5.05,5.18,5.29,1\n";

class RenderTest : public GranmemTest {
 protected:
  void SetUp() override {
    GranmemTest::SetUp();
    write_text(in_work("run.csv"), kRun);
    granmem_ok({"import", "run.csv", "--out", "run.h5", "--length-unit", "mm"});
  }
};

TEST_F(RenderTest, DrawsTheFrameWhereTheTruthSays) {
  const RunResult r = granmem_ok(
      {"render", "run.h5", "--frame", "1", "--out", "scan.tif", "--truth", "truth.csv",
       "--diameter-px", "10", "--slice-spacing-ratio", "1.5", "--bits", "16", "--no-artefacts"});
  EXPECT_TRUE(contains(r.out, "rendered 4 grains of frame 1")) << r.out;
  EXPECT_TRUE(contains(r.out, "wrote truth.csv")) << r.out;

  // Voxels of 2 mm / 10 px = 0.2 mm, slices 0.3 mm apart, recorded in the stack.
  const Stack t = read_stack(in_work("scan.tif"));
  EXPECT_EQ(t.bits, 16);
  ASSERT_TRUE(t.voxel_size);
  EXPECT_EQ(t.unit, "mm");
  EXPECT_NEAR(t.voxel_size->x(), 0.2, 1e-6);
  EXPECT_NEAR(t.voxel_size->y(), 0.2, 1e-6);
  EXPECT_NEAR(t.voxel_size->z(), 0.3, 1e-12);
  // The grains span 1.03..6.17 mm in x: 5.14 mm / 0.2 mm + 2 x 4 voxels of margin.
  EXPECT_EQ(t.nx, 34);
  EXPECT_EQ(t.ny, 34);  // 1.04..6.18 mm
  EXPECT_EQ(t.nz, 26);  // 1.07..6.29 mm: 5.22 mm / 0.3 mm + 8
  ASSERT_EQ(t.voxels.size(), std::size_t(t.nx * t.ny * t.nz));

  const Table truth = read_columns(in_work("truth.csv"),
                                   {"frame", "particle", "x", "y", "z", "radius", "ax", "edge"});
  ASSERT_EQ(truth.rows(), 4u);
  const Eigen::Vector3d voxel(0.2, 0.2, 0.3);
  const Eigen::Vector3d mm[4] = {
      {2.03, 2.11, 2.07}, {5.17, 2.04, 2.13}, {2.09, 5.12, 2.61}, {5.05, 5.18, 5.29}};
  const auto truth_at = [&](std::size_t i) {
    return Eigen::Vector3d(truth["x"].values[i], truth["y"].values[i], truth["z"].values[i]);
  };
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(truth["frame"].values[i], 1);
    EXPECT_EQ(truth["particle"].values[i], double(11 + i));
    EXPECT_NEAR(truth["radius"].values[i], 5.0, 1e-9);
    EXPECT_EQ(truth["edge"].values[i], 0);
    EXPECT_TRUE(std::isfinite(truth["ax"].values[i]));  // a random axis, drawn with the grain
    // The truth is the frame's positions in voxels: its differences are the run's, in voxels.
    const Eigen::Vector3d moved = (truth_at(i) - truth_at(0)).cwiseProduct(voxel);
    EXPECT_NEAR((moved - (mm[i] - mm[0])).norm(), 0, 1e-9) << "grain " << 11 + i;
    // The stack is centred on the grains' extent.
    const Eigen::Vector3d centre_voxel =
        (Eigen::Vector3d(t.nx, t.ny, t.nz).array() - 1).matrix() / 2;
    const Eigen::Vector3d centre_mm(3.6, 3.61, 3.68);
    EXPECT_NEAR((truth_at(i) - centre_voxel - (mm[i] - centre_mm).cwiseQuotient(voxel)).norm(), 0,
                1e-9);
  }

  // The image: around each truth position, a dark grain of the right volume, centred there.
  const double fluid = std::floor(0.75 * 65535 + 0.5), grain = std::floor(0.15 * 65535 + 0.5);
  const double holed = 4.0 / 3 * M_PI * std::pow(1 - 0.3 * 0.3, 1.5);  // mm^3, hole bored out
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector3d c = truth_at(i);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0;
    for (std::int64_t z = 0; z < t.nz; ++z) {
      for (std::int64_t y = 0; y < t.ny; ++y) {
        for (std::int64_t x = 0; x < t.nx; ++x) {
          const Eigen::Vector3d p = Eigen::Vector3d(double(x), double(y), double(z));
          if ((p - c).cwiseProduct(voxel).norm() > 1.45) continue;  // mm: grain + sampling
          const double phi = (fluid - t.at(x, y, z)) / (fluid - grain);
          sum += phi * p;
          total += phi;
        }
      }
    }
    EXPECT_NEAR(total * voxel.prod() / holed, 1.0, 2e-3) << "grain " << 11 + i;
    EXPECT_LT((sum / total - c).cwiseAbs().maxCoeff(), 1e-3) << "grain " << 11 + i;
  }
}

TEST_F(RenderTest, ArtefactsAreSeededAndAdjustable) {
  granmem_ok({"render", "run.h5", "--frame", "0", "--out", "a.tif", "--seed", "4"});
  granmem_ok({"render", "run.h5", "--frame", "0", "--out", "b.tif", "--seed", "4"});
  granmem_ok({"render", "run.h5", "--frame", "0", "--out", "c.tif", "--seed", "5"});
  EXPECT_EQ(read_text(in_work("a.tif")), read_text(in_work("b.tif")));
  EXPECT_NE(read_text(in_work("a.tif")), read_text(in_work("c.tif")));
  // Defaults: 12 px grains, slices 1.5 px apart, 8 bits.
  const Stack a = read_stack(in_work("a.tif"));
  EXPECT_EQ(a.bits, 8);
  ASSERT_TRUE(a.voxel_size);
  EXPECT_NEAR(a.voxel_size->x(), 1 / 6.0, 1e-6);
  EXPECT_NEAR(a.voxel_size->z(), 0.25, 1e-12);
  // Only noise, no blur and a fluid of 0.5: the fluid's spread is the read noise's.
  granmem_ok({"render",        "run.h5", "--frame",   "0", "--out",     "n.tif",
              "--bits",        "16",     "--blur",    "0", "--noise",   "0.02,0",
              "--attenuation", "0",      "--flicker", "0", "--streaks", "0",
              "--fluid-level", "0.5"});
  const Stack n = read_stack(in_work("n.tif"));
  double s = 0, s2 = 0, count = 0;
  for (std::int64_t y = 0; y < n.ny; ++y) {
    for (std::int64_t x = 0; x < n.nx; ++x) {  // slice 0: in the margin, fluid only
      const double v = n.at(x, y, 0) / 65535.0;
      s += v;
      s2 += v * v;
      ++count;
    }
  }
  const double mean = s / count, sigma = std::sqrt(s2 / count - mean * mean);
  EXPECT_NEAR(mean, 0.5, 0.002);
  EXPECT_NEAR(sigma, 0.02, 0.002);
}

TEST_F(RenderTest, OptionsFromTheConfigFile) {
  write_text(in_work("render.toml"),
             "[render]\nframe = 0\nout = \"c.tif\"\ntruth = \"c.csv\"\ndiameter-px = 8\n"
             "slice-spacing-ratio = 1\nbits = 16\nno-artefacts = true\n");
  const RunResult r = granmem_ok({"--config", "render.toml", "render", "run.h5"});
  EXPECT_TRUE(contains(r.out, "no artefacts")) << r.out;
  const Stack t = read_stack(in_work("c.tif"));
  EXPECT_EQ(t.bits, 16);
  ASSERT_TRUE(t.voxel_size);
  EXPECT_NEAR(t.voxel_size->x(), 0.25, 1e-6);
  const Table truth = read_columns(in_work("c.csv"), {"frame", "radius"});
  ASSERT_EQ(truth.rows(), 4u);
  EXPECT_EQ(truth["frame"].values[0], 0);
  EXPECT_NEAR(truth["radius"].values[0], 4.0, 1e-9);
  // The command line wins over the file.
  granmem_ok({"--config", "render.toml", "render", "run.h5", "--bits", "8", "--out", "d.tif"});
  EXPECT_EQ(read_stack(in_work("d.tif")).bits, 8);
}

TEST_F(RenderTest, BadInputSaysWhatAndWritesNothing) {
  const auto expect_clean_failure = [&](const std::vector<std::string>& args,
                                        const std::string& says) {
    const auto before = snapshot(work());
    const RunResult r = granmem(args);
    EXPECT_NE(r.exit_code, 0);
    ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
    EXPECT_TRUE(contains(r.err, "granmem: error: ")) << r.err;
    EXPECT_TRUE(contains(r.err, says)) << r.err;
    EXPECT_EQ(snapshot(work()), before) << r.err;
  };
  const std::vector<std::string> base = {"render", "run.h5", "--out", "x.tif", "--truth", "x.csv"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  expect_clean_failure(with({"--frame", "7"}), "--frame 7: run.h5 has no such frame");
  expect_clean_failure(with({"--frame", "1", "--bits", "12"}), "--bits");
  expect_clean_failure(with({"--frame", "1", "--noise", "loud"}), "--noise");
  expect_clean_failure(with({"--frame", "1", "--blur", "1,2"}), "--blur");
  expect_clean_failure(with({"--frame", "1", "--flicker=-0.1"}), "flicker must be >= 0");
  expect_clean_failure(with({"--frame", "1", "--hole-fraction", "1.5"}), "hole_fraction");
  expect_clean_failure(with({"--frame", "1", "--voxel-size", "0.1,0.1,0.2s"}), "--voxel-size");
  expect_clean_failure(with({"--frame", "1", "--wall", "z,3"}), "--wall");
  expect_clean_failure(with({"--frame", "1", "--no-artefacts", "--blur", "1"}), "--blur");
  expect_clean_failure({"render", "run.h5", "--out", "x.tif"}, "--frame");
  expect_clean_failure({"render", "missing.h5", "--frame", "0", "--out", "x.tif"}, "missing.h5");
  expect_clean_failure(
      {"render", "run.h5", "--frame", "1", "--out", "x.tif", "--truth", "no/x.csv"},
      "folder 'no' does not exist");
}

}  // namespace
}  // namespace granmem::testing
