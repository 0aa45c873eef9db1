// calibrate()'s twin where the options leave it: the design measured for each fit
// (docs/CALIBRATION.md), and what the caller gives kept.
#include <gtest/gtest.h>

#include <vector>

#include "granmem/calibration/calibrate.hpp"

namespace granmem {
namespace {

TEST(CalibrateOptions, EachFitGetsTheDesignMeasuredForIt) {
  CalibrateOptions steady;
  steady.observables = CalibrationObservables::steady_state;
  const CalibrateOptions s = steady.with_default_design();
  EXPECT_EQ(s.mu_s, (std::vector<double>{0.05, 0.1, 0.2, 0.4}));
  EXPECT_EQ(s.replicas, 3);  // 12 runs: the grid of the steady-state pseudo-experiments
  EXPECT_NO_THROW(s.validate());
  const CalibrateOptions d = CalibrateOptions{}.with_default_design();
  EXPECT_EQ(d.mu_s, (std::vector<double>{0.03, 0.05, 0.08, 0.12, 0.2, 0.3, 0.5}));
  EXPECT_EQ(d.replicas, 2);
  CalibrateOptions joint = steady;
  joint.mu_r = {0.004, 0.012, 0.036};
  const CalibrateOptions j = joint.with_default_design();
  EXPECT_EQ(j.mu_s, (std::vector<double>{0.05, 0.12, 0.3}));
  EXPECT_EQ(j.replicas, 2);  // x 3 mu_r: the 18 runs of the measured joint fits
  steady.mu_s = {0.05, 0.14, 0.4};
  steady.replicas = 4;
  const CalibrateOptions given = steady.with_default_design();
  EXPECT_EQ(given.mu_s, steady.mu_s);
  EXPECT_EQ(given.replicas, 4);
}

}  // namespace
}  // namespace granmem
