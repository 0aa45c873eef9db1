// A run's own errors as the calibration reads them: the RMS of the per-grain standard
// errors its store carries, over every frame, unknown ones left out.
#include "granmem/calibration/scan_errors.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "temp_dir.hpp"

namespace granmem {
namespace {

class ScanErrorsTest : public testing::TempDirTest {};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

RunHeader two_grains(bool errors) {
  RunHeader h;
  h.length_unit = "mm";
  h.id = {1, 2};
  h.radius = {2.5, 2.5};
  h.has_axis = true;
  h.has_position_error = h.has_axis_error = errors;
  return h;
}

TEST_F(ScanErrorsTest, TheRootMeanSquareOfTheKnownStandardErrors) {
  Trajectories run;
  run.header = two_grains(true);
  Frame a = Frame::unknown(run.header), b = Frame::unknown(run.header);
  a.position.setZero();
  b.position.setZero();
  a.position_error.row(0) << 0.03, 0.04, 0.01;
  a.position_error.row(1) << 0.04, 0.03, kNaN;  // incomplete: left out
  b.position_error.row(1) << 0.04, 0.03, 0.07;
  a.axis_error = {0.003, kNaN};
  b.axis_error = {0.004, 0.0};
  b.step = 1;
  run.frames = {a, b};
  write_trajectories(path("scans.h5"), run);
  const ScanErrors e = scan_errors(TrajectoryReader(path("scans.h5")));
  EXPECT_EQ(e.positions, 2u);
  EXPECT_DOUBLE_EQ(e.position.x(), std::sqrt((0.03 * 0.03 + 0.04 * 0.04) / 2));
  EXPECT_DOUBLE_EQ(e.position.y(), std::sqrt((0.04 * 0.04 + 0.03 * 0.03) / 2));
  EXPECT_DOUBLE_EQ(e.position.z(), std::sqrt((0.01 * 0.01 + 0.07 * 0.07) / 2));
  EXPECT_EQ(e.axes, 3u);
  EXPECT_DOUBLE_EQ(e.axis, std::sqrt((0.003 * 0.003 + 0.004 * 0.004) / 3));
}

TEST_F(ScanErrorsTest, ARunWithoutThemHasNone) {
  Trajectories run;
  run.header = two_grains(false);
  Frame f = Frame::unknown(run.header);
  f.position.setZero();
  run.frames = {f};
  write_trajectories(path("sim.h5"), run);
  const ScanErrors e = scan_errors(TrajectoryReader(path("sim.h5")));
  EXPECT_TRUE(e.position.array().isNaN().all());
  EXPECT_TRUE(std::isnan(e.axis));
  EXPECT_EQ(e.positions + e.axes, 0u);
}

}  // namespace
}  // namespace granmem
