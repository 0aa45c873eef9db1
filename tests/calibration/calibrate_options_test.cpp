// calibrate()'s twin where the options leave it: the design measured for each fit
// (docs/CALIBRATION.md), and what the caller gives kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "granmem/calibration/calibrate.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

TEST(CalibrateOptions, EachFitGetsTheDesignMeasuredForIt) {
  CalibrateOptions steady;  // the steady state: the default observables
  EXPECT_EQ(steady.observables, CalibrationObservables::steady_state);
  const CalibrateOptions s = steady.with_default_design();
  EXPECT_EQ(s.mu_s, (std::vector<double>{0.05, 0.14, 0.4}));
  EXPECT_EQ(s.replicas, 3);  // 12 runs: the refined design of the poured pseudo-experiments
  EXPECT_EQ(s.refine, 3);
  EXPECT_NO_THROW(s.validate());
  CalibrateOptions placed = steady;
  placed.preparation = TwinPreparation::experiment;
  const CalibrateOptions p = placed.with_default_design();
  EXPECT_EQ(p.mu_s, (std::vector<double>{0.05, 0.13, 0.35, 0.6}));
  EXPECT_EQ(p.replicas, 2);  // placed replicas scatter little
  EXPECT_EQ(p.refine, 4);    // 12 runs: 8 reaching past 0.4, 4 where those fit
  EXPECT_NO_THROW(p.validate());
  CalibrateOptions unrefined = placed;  // the design, without its second stage
  unrefined.refine = 0;
  EXPECT_EQ(unrefined.with_default_design().refine, 0);
  EXPECT_EQ(unrefined.with_default_design().mu_s.size(), 4u);
  CalibrateOptions displacements;
  displacements.observables = CalibrationObservables::displacements;
  const CalibrateOptions d = displacements.with_default_design();
  EXPECT_EQ(d.mu_s, (std::vector<double>{0.03, 0.05, 0.08, 0.12, 0.2, 0.3, 0.5}));
  EXPECT_EQ(d.replicas, 2);
  CalibrateOptions joint = steady;
  joint.mu_r = {0.004, 0.012, 0.036};
  const CalibrateOptions j = joint.with_default_design();
  EXPECT_EQ(j.mu_s, (std::vector<double>{0.05, 0.12, 0.3}));
  EXPECT_EQ(j.replicas, 2);  // x 3 mu_r: the 18 runs of the measured joint fits
  steady.mu_s = {0.05, 0.1, 0.2, 0.4};
  steady.replicas = 4;
  const CalibrateOptions given = steady.with_default_design();
  EXPECT_EQ(given.mu_s, steady.mu_s);
  EXPECT_EQ(given.replicas, 4);
  EXPECT_EQ(given.refine, 0);  // a design given is run as given
  placed.mu_s = steady.mu_s;   // a placed design given is run as given: refined if asked
  EXPECT_EQ(placed.with_default_design().refine, 0);
  placed.refine = 2;
  EXPECT_EQ(placed.with_default_design().refine, 2);
}

TEST(CalibrateOptions, APlacedTwinsRefinedPackingsHoldTheTrendOnBothSidesOfItsFit) {
  CalibrateOptions placed;
  placed.preparation = TwinPreparation::experiment;
  placed = placed.with_default_design();  // 0.05, 0.13, 0.35, 0.6
  // Four: one a factor 1.15 below the fit, one above, two at it (their scatter there).
  std::vector<double> mu = placed.refined_mu_s(0.28, 4);
  ASSERT_EQ(mu.size(), 4u);
  EXPECT_NEAR(mu[0], 0.28 / 1.15, 1e-12);
  EXPECT_EQ(mu[1], 0.28);
  EXPECT_EQ(mu[2], 0.28);
  EXPECT_NEAR(mu[3], 0.28 * 1.15, 1e-12);
  // Three (the fourth the placement probe): one on each side and one at the fit.
  const std::vector<double> three = placed.refined_mu_s(0.28, 3);
  EXPECT_NEAR(three[0], 0.28 / 1.15, 1e-12);
  EXPECT_EQ(three[1], 0.28);
  EXPECT_NEAR(three[2], 0.28 * 1.15, 1e-12);
  EXPECT_EQ(placed.refined_mu_s(0.28, 1), (std::vector<double>{0.28}));
  // Near the design's end: no farther than halfway (in ln mu_s) to it, so inside it.
  mu = placed.refined_mu_s(0.55, 2);
  EXPECT_NEAR(mu.front(), 0.55 / 1.15, 1e-12);
  EXPECT_NEAR(mu.back(), std::sqrt(0.55 * 0.6), 1e-12);
  mu = placed.refined_mu_s(0.055, 2);
  EXPECT_NEAR(mu.front(), std::sqrt(0.055 * 0.05), 1e-12);
  // A poured twin's stay at the fit, where they measure its packings' scatter.
  CalibrateOptions poured;
  poured.preparation = TwinPreparation::each;
  poured = poured.with_default_design();
  EXPECT_EQ(poured.refined_mu_s(0.2, 3), (std::vector<double>(3, 0.2)));
}

class ResolvedOptions : public testing::TempDirTest {
 protected:
  // A two-grain store of 5 mm grains with frames of cycles 0 to `last` (but `missing`): a
  // simulation's (orientations), or a scan's (positions' standard errors of `error`, m).
  std::filesystem::path store(bool scan, double error = 0, std::int64_t last = 0,
                              std::int64_t missing = -1) {
    Trajectories t;
    t.header.id = {1, 2};
    t.header.radius = {0.0025, 0.0025};
    t.header.box = Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.02, 0.02, 0.04)};
    t.header.has_orientation = !scan;
    t.header.has_position_error = scan;
    Frame f = Frame::unknown(t.header);
    f.position << 0.005, 0.005, 0.0025, 0.012, 0.005, 0.0025;
    if (scan) {
      f.position_error.setConstant(error);
    } else {
      f.orientation.setZero();
      f.orientation.col(0).setOnes();  // the identity
    }
    for (std::int64_t cycle = 0; cycle <= last; ++cycle) {
      f.step = cycle;
      if (cycle != missing) t.frames.push_back(f);
    }
    const auto p = path((scan ? "scan_" + std::to_string(error) : std::string("sim")) + "_" +
                        std::to_string(last) + "_" + std::to_string(missing) + ".h5");
    write_trajectories(p, t);
    return p;
  }
};

TEST_F(ResolvedOptions, APlacedTwinGetsItsOwnDesignAndAPouredOneItsOwn) {
  CalibrateOptions steady;
  steady.observables = CalibrationObservables::steady_state;
  const TrajectoryReader simulation(store(false));
  const CalibrateOptions placed = resolved_options(steady, simulation);
  EXPECT_EQ(placed.preparation, TwinPreparation::experiment);
  EXPECT_EQ(placed.mu_s.back(), 0.6);
  EXPECT_EQ(placed.replicas, 2);
  EXPECT_EQ(placed.refine, 4);
  // A coarse scan (0.005 d, as a 9-pixel render's) is poured; a fine one (0.001 d, the
  // default render's) is placed as a simulation's packing is (kPlaceableScanError).
  EXPECT_EQ(resolved_options(steady, TrajectoryReader(store(true, 5e-6))).preparation,
            TwinPreparation::experiment);
  const CalibrateOptions poured = resolved_options(steady, TrajectoryReader(store(true, 25e-6)));
  EXPECT_EQ(poured.preparation, TwinPreparation::each);
  EXPECT_EQ(poured.mu_s.back(), 0.4);
  EXPECT_EQ(poured.replicas, 3);
  EXPECT_EQ(poured.refine, 3);
  CalibrateOptions each = steady;  // a simulation poured when asked: the poured design
  each.preparation = TwinPreparation::each;
  EXPECT_EQ(resolved_options(each, simulation).mu_s.back(), 0.4);
  steady.mu_s = {0.1, 0.2, 0.4};  // a design given is kept, placed or not
  steady.replicas = 3;
  const CalibrateOptions given = resolved_options(steady, simulation);
  EXPECT_EQ(given.mu_s, steady.mu_s);
  EXPECT_EQ(given.replicas, 3);
  EXPECT_EQ(given.refine, 0);
}

// One cycle ahead is the default where it can be and nothing asked is the window fit's: a
// placed twin fitting mu_s over a window of 5 cycles or more (kOneCycleAheadByDefault) whose
// every cycle and the one before it the experiment holds placeable.
TEST_F(ResolvedOptions, OneCycleAheadIsTheDefaultWhereEveryCyclesFrameIsThere) {
  const CalibrateOptions o;
  const TrajectoryReader six(store(false, 0, 6));  // the default window: cycles 1-6
  const CalibrateOptions ahead = resolved_options(o, six);
  EXPECT_TRUE(ahead.ahead());
  EXPECT_EQ(ahead.refine, 0);  // its packing ahead, not the refined packings
  EXPECT_NO_THROW(ahead.validate());
  const auto resolved = [&](CalibrateOptions given, const TrajectoryReader& experiment) {
    return resolved_options(given, experiment);
  };
  // The window fit: a window of 4 cycles, or the main job's 3.
  CalibrateOptions four = o;
  four.window = std::pair<std::int64_t, std::int64_t>{3, 6};
  EXPECT_FALSE(resolved(four, six).ahead());
  EXPECT_EQ(resolved(four, six).refine, 4);
  EXPECT_FALSE(resolved(o, TrajectoryReader(store(false, 0, 3))).ahead());
  four.window->first = 2;  // five: ahead
  EXPECT_TRUE(resolved(four, six).ahead());
  // A frame missing in the window (2-6), or the one before it: the cycles that have theirs
  // compared, too few for the default.
  const TrajectoryReader gap(store(false, 0, 6, 4));
  EXPECT_EQ(comparable_ahead_cycles(gap, {2, 6}, 0), (std::vector<std::int64_t>{2, 3, 6}));
  EXPECT_EQ(comparable_ahead_cycles(gap, {2, 6}, 1), (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(comparable_ahead_cycles(gap, {1, 6}, 1), (std::vector<std::int64_t>{2, 3}));
  EXPECT_FALSE(resolved(four, gap).ahead());
  EXPECT_FALSE(resolved(four, TrajectoryReader(store(false, 0, 6, 1))).ahead());
  // Fine scans are placed (ahead); coarse ones poured (the window fit).
  EXPECT_TRUE(resolved(o, TrajectoryReader(store(true, 5e-6, 6))).ahead());
  EXPECT_FALSE(resolved(o, TrajectoryReader(store(true, 25e-6, 6))).ahead());
  // What the caller asks of the window fit keeps it.
  CalibrateOptions asked = o;
  asked.refine = 2;
  EXPECT_FALSE(resolved(asked, six).ahead());
  asked = o;
  asked.placed_cycle = 0;
  EXPECT_FALSE(resolved(asked, six).ahead());
  asked = o;
  asked.one_cycle_ahead = false;
  EXPECT_FALSE(resolved(asked, six).ahead());
  EXPECT_EQ(resolved(asked, six).refine, 4);
  asked = o;
  asked.mu_r = {0.004, 0.012, 0.036};  // the joint fit
  EXPECT_FALSE(resolved(asked, six).ahead());
  asked = o;
  asked.observables = CalibrationObservables::displacements;
  EXPECT_FALSE(resolved(asked, six).ahead());
}

// A placed twin starts before the window; from scans, at their first frame, the preparation,
// where it holds the packing: settling centres off by a scan's error into a packing the
// drive has trained undoes that training (docs/CALIBRATION.md, session 38).
TEST_F(ResolvedOptions, ScansArePlacedFromTheirPreparation) {
  CalibrateOptions o;
  o.window = std::pair<std::int64_t, std::int64_t>{3, 4};
  EXPECT_EQ(placed_cycle_for(o, TrajectoryReader(store(false, 0, 4))), 2);
  EXPECT_EQ(placed_cycle_for(o, TrajectoryReader(store(true, 5e-6, 4))), 0);
  // Too coarse a scan to place at its preparation: before the window, as a simulation.
  EXPECT_EQ(placed_cycle_for(o, TrajectoryReader(store(true, 25e-6, 4))), 2);
  o.placed_cycle = 1;  // given: kept
  EXPECT_EQ(placed_cycle_for(o, TrajectoryReader(store(true, 5e-6, 4))), 1);
}

}  // namespace
}  // namespace granmem
