// The friction series runner: each run is the protocol at its friction, whatever runs
// beside it, and a stop flag stops the series with a clear error and no run taken for
// finished.
#include "granmem/calibration/friction_series.hpp"

#include <gtest/gtest.h>

#include <atomic>

#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/simulate_settings.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class FrictionSeriesTest : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    RunSettings v = default_simulate_settings();
    v["grains"] = "60";
    v["box"] = "2cm";
    v["lid-mass"] = "0.2kg";
    v["amplitude"] = "5%";
    v["period"] = "0.05s";
    physics_ = physics_from(v);
    deposit_ = deposit_from(v);
    series_.protocol.cycles = 2;
    series_.protocol.drive = drive_from(v, physics_, deposit_.box_side, deposit_.box_side,
                                        deposit_.lid_mass, deposit_.radius);
    series_.protocol.parameters["simulate/grains"] = "60";
  }
  std::vector<std::filesystem::path> run(const std::vector<FrictionRunSpec>& specs,
                                         const std::string& dir, int parallel) {
    FrictionSeriesOptions o = series_;
    o.dir = path(dir);
    std::filesystem::create_directories(o.dir);
    o.parallel = parallel;
    return run_friction_series(specs, o, [&](const FrictionRunSpec& spec, int cores) {
      return deposit_at_friction(deposit_, physics_, spec, o.walls_follow, cores);
    });
  }
  PhysicsOptions physics_;
  DepositOptions deposit_;
  FrictionSeriesOptions series_;
};

TEST_F(FrictionSeriesTest, EachRunIsTheProtocolAtItsFrictionWhateverRunsBesideIt) {
  const std::vector<FrictionRunSpec> specs{{0.1, 1}, {0.4, 1}, {0.4, 2}};
  const auto paths = run(specs, "series", 2);
  ASSERT_EQ(paths.size(), 3u);
  for (std::size_t k = 0; k < specs.size(); ++k) {
    EXPECT_EQ(paths[k], friction_run_path(path("series"), specs[k]));
    EXPECT_TRUE(finished_run(paths[k], series_.protocol.parameters, 2)) << paths[k];
    const Trajectories t = read_trajectories(paths[k]);
    EXPECT_EQ(t.frames.size(), 3u);  // the packing before the first cycle, then 2
    EXPECT_EQ(std::stod(t.header.parameters.at("calibrate/mu_s")), specs[k].mu_s);
  }
  // Alone and on one thread: the same run, bit for bit.
  const auto alone = run({specs[1]}, "alone", 1);
  const Trajectories a = read_trajectories(paths[1]), b = read_trajectories(alone[0]);
  EXPECT_EQ(a.frames.back().position, b.frames.back().position);
  // Another friction, or another packing, is another run.
  const Trajectories c = read_trajectories(paths[0]), d = read_trajectories(paths[2]);
  EXPECT_NE(a.frames.back().position, c.frames.back().position);
  EXPECT_NE(a.frames.back().position, d.frames.back().position);
}

TEST_F(FrictionSeriesTest, AStopFlagStopsTheSeriesAndNoRunPassesForFinished) {
  std::atomic<bool> stop{true};
  series_.stop = &stop;
  const std::vector<FrictionRunSpec> specs{{0.1, 1}, {0.4, 1}};
  try {
    run(specs, "stopped", 2);
    FAIL() << "a stopped series returned";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("stopped"), std::string::npos) << e.what();
  }
  for (const FrictionRunSpec& s : specs) {
    const auto p = friction_run_path(path("stopped"), s);
    EXPECT_FALSE(std::filesystem::exists(p) && finished_run(p, series_.protocol.parameters, 2));
  }
}

}  // namespace
}  // namespace granmem
