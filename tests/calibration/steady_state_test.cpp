// The steady state of a run: window means of the rotation, the bulk structure from
// positions and the store's own observables, on a run whose every value is known.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "checks.hpp"
#include "granmem/calibration/comparison.hpp"
#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

constexpr double kTurn = 0.02;  // rad per cycle, about x

// A simple cubic packing of 1 mm grains, 1 mm apart (touching), turning every grain's
// cavity axis by kTurn each cycle and shifting it by 0.01 mm; the store's observables
// say 10 c (wall force) and 0.5 + 0.01 c (packing fraction) at cycle c.
Trajectories cubic_run() {
  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = "mm";
  h.time_unit = "cycle";
  h.has_axis = true;
  const int n = 8;
  h.box = Box{Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d(n, n, 20)};  // 8 x 8 mm
  for (int k = 0; k < n * n * n; ++k) {
    h.id.push_back(k);
    h.radius.push_back(0.5);
  }
  for (int c = 0; c <= 4; ++c) {
    Frame f = Frame::unknown(h);
    f.step = c;
    f.time = c;
    for (int k = 0; k < n * n * n; ++k) {
      f.position.row(k) << k % n + 0.01 * c, (k / n) % n, k / (n * n);
      f.axis.row(k) << 0, -std::sin(kTurn * c), std::cos(kTurn * c);
    }
    run.frames.push_back(f);
    // At full compression, at the cycle's end (unloaded), and the lid's packing fraction.
    const std::pair<const char*, double> stored[] = {{"wall_force_full_compression", 10.0 * c},
                                                     {"wall_force", 2.0 - 0.1 * c},
                                                     {"packing_fraction", 0.5 + 0.01 * c}};
    for (const auto& [name, value] : stored) {
      Observable& o = run.observables[name];
      o.unit = name[0] == 'w' ? "N" : "1";
      o.step.push_back(c);
      o.time.push_back(c);
      o.value.push_back(value);
    }
  }
  return run;
}

class SteadyStateTest : public testing::TempDirTest {
 protected:
  // cubic_run() written to the store and read back.
  TrajectoryReader cubic_store() {
    write_trajectories(path("run.h5"), cubic_run());
    return TrajectoryReader(path("run.h5"));
  }
};

TEST_F(SteadyStateTest, WindowMeansOfTheRotationTheStructureAndTheStoresObservables) {
  const TrajectoryReader run = cubic_store();
  ObservableOptions o;
  o.window = {3, 4};
  const SteadyState s = steady_state(run, cycle_observables(run, o));
  EXPECT_EQ(s.names,
            (std::vector<std::string>{"dr", "rot_disp", "bulk_packing_fraction", "coordination",
                                      "height_packing_fraction", "packing_fraction",
                                      "wall_force_full_compression", "wall_force_unloaded"}));
  EXPECT_NEAR(s["dr"], 0.01, 1e-12);             // every grain 0.01 mm along x, in diameters
  EXPECT_NEAR(s["rot_disp"], kTurn / 2, 1e-12);  // angle x d/2, in diameters
  EXPECT_NEAR(s["bulk_packing_fraction"], M_PI / 6, 1e-12);
  EXPECT_DOUBLE_EQ(s["coordination"], 6);
  EXPECT_NEAR(s["height_packing_fraction"], M_PI / 6, 1e-12);  // 8 layers on 8 x 8 mm
  EXPECT_DOUBLE_EQ(s["packing_fraction"], 0.535);              // cycles 3 and 4 only
  EXPECT_DOUBLE_EQ(s["wall_force_full_compression"], 35);
  EXPECT_DOUBLE_EQ(s["wall_force_unloaded"], 1.65);  // the store's wall_force, cycles 3-4
  EXPECT_TRUE(std::isnan(s["lid_height"]));
  // Across the window (cycles 3 to 4): the store's values rise by 0.01 and 10 per cycle,
  // the rotation per cycle and the lattice do not change.
  EXPECT_NEAR(s.drift_of("packing_fraction"), 0.01, 1e-12);
  EXPECT_NEAR(s.drift_of("wall_force_full_compression"), 10, 1e-12);
  EXPECT_NEAR(s.drift_of("wall_force_unloaded"), -0.1, 1e-12);
  EXPECT_NEAR(s.drift_of("rot_disp"), 0, 1e-12);
  EXPECT_NEAR(s.drift_of("dr"), 0, 1e-12);
  EXPECT_NEAR(s.drift_of("height_packing_fraction"), 0, 1e-12);
}

// A scan's hole axes carry an error; the twin's exact axes get one like it: each axis
// tilted at random by sigma in each direction across it, so that a turn of kTurn between
// two frames is measured as the Rice-distributed angle between two noisy axes, whose mean
// square is kTurn^2 + 4 sigma^2. The same seed gives the same angles.
TEST_F(SteadyStateTest, AnAxisNoiseAddsToTheRotationsAsAScansError) {
  const TrajectoryReader run = cubic_store();
  ObservableOptions o;
  o.window = {1, 4};
  const CycleObservables exact = cycle_observables(run, o);
  o.axis_noise = 0.02;
  const CycleObservables noisy = cycle_observables(run, o);
  ASSERT_EQ(noisy.rot_disp.size(), exact.rot_disp.size());
  double mean_square = 0;
  for (double r : noisy.rot_disp)
    mean_square += std::pow(2 * r, 2) / double(noisy.rot_disp.size());  // angle = 2 rot / d
  EXPECT_NEAR(mean_square, kTurn * kTurn + 4 * 0.02 * 0.02, 0.08 * 0.002);
  for (double r : exact.rot_disp)
    EXPECT_NEAR(r, kTurn / 2, 1e-12);
  EXPECT_EQ(noisy.dr, exact.dr);  // positions are not touched
  EXPECT_EQ(cycle_observables(run, o).rot_disp, noisy.rot_disp);
}

// A scan's locating error adds to the displacements: each frame's positions moved by sigma
// along every axis give a displacement an error of sigma sqrt(2) per component, so the mean
// |dr| of the lattice's uniform 0.01 mm steps under sigma = 0.1 mm is the mean of a
// noncentral chi with 3 degrees of freedom, s sqrt(8 / pi) (1 + (0.01 / s)^2 / 6), s = sigma
// sqrt(2): 0.2259 mm (2,048 displacements: to ~1 %). The rotations are untouched.
TEST_F(SteadyStateTest, ALocatingErrorAddsToTheDisplacementsAsAScansError) {
  const TrajectoryReader run = cubic_store();
  ObservableOptions o;
  o.window = {1, 4};
  const CycleObservables exact = cycle_observables(run, o);
  o.position_noise = Eigen::Vector3d::Constant(0.1e-3);  // m
  const CycleObservables noisy = cycle_observables(run, o);
  const double s = 0.1 * std::sqrt(2.0);
  EXPECT_NEAR(summarize(noisy.dr).mean, s * std::sqrt(8 / M_PI) * (1 + std::pow(0.01 / s, 2) / 6),
              0.008);
  for (double dr : exact.dr)
    EXPECT_NEAR(dr, 0.01, 1e-12);
  EXPECT_EQ(noisy.rot_disp, exact.rot_disp);
}

// A scan's located radii come out small (blur, threshold): measured at the grains' known
// radius, the structure is the lattice's again; at the located radii it is not.
TEST_F(SteadyStateTest, TheStructureIsMeasuredAtTheGrainsKnownRadiusWhenGiven) {
  Trajectories located = cubic_run();
  for (double& r : located.header.radius)
    r *= 0.95;
  write_trajectories(path("scan.h5"), located);
  const TrajectoryReader run(path("scan.h5"));
  ObservableOptions o;
  o.window = {3, 4};
  const CycleObservables observed = cycle_observables(run, o);
  const SteadyState at_located = steady_state(run, observed);
  // 8 layers of grains of radius 0.475 mm, 7 + 0.95 mm from bottom to top, on 8 x 8 mm
  EXPECT_NEAR(at_located["height_packing_fraction"],
              512 * 4.0 / 3 * M_PI * std::pow(0.475, 3) / (64 * 7.95), 1e-12);
  EXPECT_DOUBLE_EQ(at_located["coordination"], 0);  // 5 % gaps: no grain touches
  const SteadyState at_known = steady_state(run, observed, {}, {0.5e-3, {}});  // m
  EXPECT_NEAR(at_known["bulk_packing_fraction"], M_PI / 6, 1e-12);
  EXPECT_DOUBLE_EQ(at_known["coordination"], 6);
  EXPECT_NEAR(at_known["height_packing_fraction"], M_PI / 6, 1e-12);
  EXPECT_NEAR(at_known["rot_disp"], kTurn / 2, 1e-12);  // rotations do not use the radius
}

// A scan misses grains (dim, blurred): each one lowers the packing fraction from the height
// by 1/N; with the count the packing holds it is the whole packing's again. The lowest and
// highest layers are kept, so the height is the packing's.
TEST_F(SteadyStateTest, GrainsAScanMissedAreCountedInThePackingsHeight) {
  Trajectories scan = cubic_run();
  const std::size_t n = scan.header.id.size();
  std::size_t missed = 0;
  for (Frame& f : scan.frames) {
    for (std::size_t i = 64; i < n - 64; i += 37, ++missed)  // not in the first or last layer
      f.position.row(Eigen::Index(i)).setConstant(std::nan(""));
  }
  missed /= scan.frames.size();
  write_trajectories(path("scan.h5"), scan);
  const TrajectoryReader run(path("scan.h5"));
  ObservableOptions o;
  o.window = {3, 4};
  const CycleObservables observed = cycle_observables(run, o);
  const double lattice = M_PI / 6;  // 8 layers of touching grains, 8 mm high
  EXPECT_NEAR(steady_state(run, observed)["height_packing_fraction"],
              lattice * double(n - missed) / double(n), 1e-12);
  EXPECT_NEAR(steady_state(run, observed, {}, {{}, n})["height_packing_fraction"], lattice, 1e-12);
}

// Locating noise opens touching pairs: on the lattice of touching grains a contact count
// within a 2 % gap falls as soon as the noise is a fraction of that gap, while the height's
// packing fraction hardly moves (its ends are many grains). No noise, no effect; the seed
// sets the moves.
TEST_F(SteadyStateTest, LocatingNoiseOpensContactsButKeepsThePackingsHeight) {
  const TrajectoryReader run = cubic_store();
  const CycleRange window{3, 4};
  const SteadyState none = structure_noise_effect(run, window, Eigen::Vector3d::Zero());
  for (double v : none.values)
    EXPECT_EQ(v, 0);
  const Eigen::Vector3d sigma = Eigen::Vector3d::Constant(0.01);  // mm: 1 % of d
  const SteadyState noisy = structure_noise_effect(run, window, sigma);
  // A bond stays within the 2 % gap while its gap, ~normal with sigma sqrt(2) x 1 %, is
  // below 0.02 d: ~92 % of a grain's 6 bonds.
  EXPECT_LT(noisy["coordination"], -0.2);
  EXPECT_GT(noisy["coordination"], -0.7);
  EXPECT_LT(std::abs(noisy["height_packing_fraction"]), 0.005);
  EXPECT_EQ(structure_noise_effect(run, window, sigma).values, noisy.values);
  EXPECT_NE(structure_noise_effect(run, window, sigma, {}, {}, 2).values, noisy.values);
  // Noise along z alone opens the vertical bonds, a third of them.
  const SteadyState along_z = structure_noise_effect(run, window, Eigen::Vector3d(0, 0, 0.01));
  EXPECT_LT(along_z["coordination"], 0);
  EXPECT_GT(along_z["coordination"], noisy["coordination"]);
}

// A twin's exact positions given a scan's locating error read the structure such scans
// read: the contacts within the 2 % gap open by what the noise check measures with the same
// draws (each bond's gap ~normal with sigma sqrt(2) x 1 % of d: Phi(sqrt 2) = 92.1 % of the
// 6 stay), while the rotation and the store's own observables, not from positions, stand.
// Zero noise: the positions as stored.
TEST_F(SteadyStateTest, PositionsGivenAScansErrorReadTheStructureSuchScansRead) {
  const TrajectoryReader run = cubic_store();
  ObservableOptions o;
  o.window = {3, 4};
  const CycleObservables observed = cycle_observables(run, o);
  const SteadyState exact = steady_state(run, observed);
  EXPECT_EQ(steady_state(run, observed, {}, {}, PositionNoise{}).values, exact.values);
  const PositionNoise noise{Eigen::Vector3d::Constant(0.01), 7};  // mm: 1 % of d
  const SteadyState scanned = steady_state(run, observed, {}, {}, noise);
  const SteadyState effect = structure_noise_effect(run, o.window, noise.sigma, {}, {}, noise.seed);
  for (const char* name : {"bulk_packing_fraction", "coordination", "height_packing_fraction"})
    EXPECT_NEAR(scanned[name], exact[name] + effect[name], 1e-12) << name;
  EXPECT_DOUBLE_EQ(exact["coordination"], 6);
  // 64 bulk grains a frame: the share over 20 draws, to ~0.004
  double kept = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed)
    kept += steady_state(run, observed, {}, {}, {noise.sigma, seed})["coordination"] / (20 * 6);
  EXPECT_NEAR(kept, 0.921, 0.012);
  for (const char* name : {"rot_disp", "wall_force_unloaded", "packing_fraction"})
    EXPECT_EQ(scanned[name], exact[name]) << name;
  const PositionNoise other_draws{noise.sigma, 8};
  EXPECT_NE(steady_state(run, observed, {}, {}, other_draws)["coordination"],
            scanned["coordination"]);
}

// A placed twin's packing read back at the frame it was placed from: that frame's structure
// alone, its positions given a scan's error as the window's are.
TEST_F(SteadyStateTest, AFramesStructureIsThatFramesAlone) {
  Trajectories t = cubic_run();
  for (Eigen::Index k = 0; k < t.frames[2].position.rows(); ++k)
    t.frames[2].position(k, 2) *= 1.1;  // cycle 2: the layers 0.1 d apart
  write_trajectories(path("stretched.h5"), t);
  const TrajectoryReader run(path("stretched.h5"));
  const SteadyState touching = frame_structure(run, 1);
  EXPECT_NEAR(touching["bulk_packing_fraction"], M_PI / 6, 1e-12);
  EXPECT_DOUBLE_EQ(touching["coordination"], 6);
  EXPECT_NEAR(touching["height_packing_fraction"], M_PI / 6, 1e-12);
  const SteadyState apart = frame_structure(run, 2);
  EXPECT_DOUBLE_EQ(apart["coordination"], 4);  // the layers no longer touch
  EXPECT_LT(apart["height_packing_fraction"], M_PI / 6 / 1.05);
  EXPECT_THROW(frame_structure(run, 7), Error);
  // Given a scan's error: the frame's values moved as the noise check moves them.
  const PositionNoise noise{Eigen::Vector3d(0.01, 0.01, 0.02), 5};
  const SteadyState noisy = frame_structure(run, 1, {}, {}, noise);
  const SteadyState moved = structure_noise_effect(run, {1, 1}, noise.sigma, {}, {}, noise.seed);
  for (const std::string& name : moved.names)
    EXPECT_NEAR(noisy[name], touching[name] + moved[name], 1e-12) << name;
  // The packing's height at the frame before a window, beside the window's: that frame's
  // alone, read back (for its read-back and noise) as the structure it is.
  SteadyState s;
  add_height_before_window(s, run, 2);
  add_height_before_window(s, run, 1, {}, noise);
  EXPECT_EQ(s.names, std::vector<std::string>(2, "height_packing_fraction_before_window"));
  EXPECT_DOUBLE_EQ(s.values[0], apart["height_packing_fraction"]);
  EXPECT_DOUBLE_EQ(s.values[1], noisy["height_packing_fraction"]);
  EXPECT_EQ(s.drift, std::vector<double>(2, 0.0));
  EXPECT_EQ(structure_read_as(s.names[0]), "height_packing_fraction");
  EXPECT_EQ(structure_read_as("height_packing_fraction"), "height_packing_fraction");
  EXPECT_EQ(structure_read_as("_before_window"), "_before_window");
  EXPECT_THROW(add_height_before_window(s, run, 7), Error);
}

// compare's options (the window and wall distance it pools these observables with),
// checked before either run is read: the defaults with a folder pass.
TEST(CompareOptions, ValidateNamesTheBadOptionAndPassesTheDefaults) {
  CompareOptions o;
  EXPECT_EQ(testing::error_message([&] { o.validate(); }), "compare: no output folder (--out)");
  o.dir = "compare";
  EXPECT_NO_THROW(o.validate());
  CompareOptions window = o;
  window.window = std::make_pair(std::int64_t(9), std::int64_t(3));
  EXPECT_EQ(testing::error_message([&] { window.validate(); }),
            "window 9:3: the first cycle is after the last");
  CompareOptions diameter = o;
  diameter.diameter = 0.0;
  EXPECT_EQ(testing::error_message([&] { diameter.validate(); }),
            "--diameter: expected a positive length");
  CompareOptions wall = o;
  wall.wall_distance = std::nan("");
  EXPECT_EQ(testing::error_message([&] { wall.validate(); }),
            "--wall-distance: expected a length >= 0");
}

}  // namespace
}  // namespace granmem
