// `simulate --engine lammps`: granmem's protocol run by LAMMPS (Debian's lmp) on the packing
// granmem deposited. Two integrators of one contact law from one packing agree over a
// couple of cycles (chaos has not yet separated them), several ranks give one rank's run,
// and what LAMMPS cannot run as granmem does is refused before any work.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
using testing::GranmemTest;

class LammpsEngine : public GranmemTest {};

// 150 grains in a 2.5 cm box under the paper's lid pressure, A = 1 %, the automatic
// (quasi-static) period: 7,309 steps a cycle.
std::vector<std::string> small_run(const std::string& out, const std::string& cycles) {
  return {"simulate", "--grains", "150", "--box", "2.5cm", "--cycles", cycles, "--out", out};
}

#ifdef GRANMEM_LAMMPS_EXE
std::vector<std::string> on_lammps(std::vector<std::string> args) {
  for (const char* a : {"--engine", "lammps", "--lammps", GRANMEM_LAMMPS_EXE})
    args.push_back(a);
  return args;
}

double mean_displacement(const Frame& from, const Frame& to) {
  return (to.position - from.position).rowwise().norm().mean();
}

// Mean angle (rad) between the cavity axes, taken as lines.
double mean_axis_turn(const Frame& from, const Frame& to) {
  double sum = 0;
  for (Eigen::Index i = 0; i < from.axis.rows(); ++i)
    sum += std::acos(std::min(1.0, std::abs(from.axis.row(i).dot(to.axis.row(i)))));
  return sum / double(from.axis.rows());
}

const Observable& observed(const Trajectories& run, const std::string& name) {
  return run.observables.at(name);
}
#endif

TEST_F(LammpsEngine, RunsTheProtocolAndAgreesWithTheEmbeddedDem) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  granmem_ok(small_run("dem.h5", "2"));
  granmem_ok(on_lammps(small_run("lmp.h5", "2")));
  const Trajectories dem = read_trajectories(in_work("dem.h5"));
  const Trajectories lmp = read_trajectories(in_work("lmp.h5"));
  ASSERT_EQ(lmp.frames.size(), 3u);
  EXPECT_TRUE(lmp.header.has_axis);
  EXPECT_FALSE(lmp.header.has_orientation);  // LAMMPS carries one body axis
  EXPECT_EQ(lmp.header.parameters.at("simulate/engine"), "lammps");
  EXPECT_EQ(lmp.header.id, dem.header.id);
  // The same packing before the first cycle (granmem's deposit, through the data file).
  EXPECT_LT((lmp.frames[0].position - dem.frames[0].position).cwiseAbs().maxCoeff(), 1e-12);
  for (std::size_t k = 1; k < 3; ++k) {
    SCOPED_TRACE("cycle " + std::to_string(k));
    EXPECT_EQ(lmp.frames[k].step, std::int64_t(k));
    // Measured: displacements within 3 %, axis turns within 4 %, the lid within 2e-4 of
    // its height, the force at full compression within 2 %.
    const double d_dem = mean_displacement(dem.frames[0], dem.frames[k]);
    const double d_lmp = mean_displacement(lmp.frames[0], lmp.frames[k]);
    EXPECT_NEAR(d_lmp / d_dem, 1.0, 0.1) << d_lmp << " m vs " << d_dem << " m";
    const double t_dem = mean_axis_turn(dem.frames[0], dem.frames[k]);
    const double t_lmp = mean_axis_turn(lmp.frames[0], lmp.frames[k]);
    EXPECT_NEAR(t_lmp / t_dem, 1.0, 0.15) << t_lmp << " rad vs " << t_dem << " rad";
    for (const char* name : {"lid_height", "packing_fraction"}) {
      EXPECT_NEAR(observed(lmp, name).value[k] / observed(dem, name).value[k], 1.0, 1e-3) << name;
    }
    const double f_dem = observed(dem, "wall_force_full_compression").value[k];
    const double f_lmp = observed(lmp, "wall_force_full_compression").value[k];
    EXPECT_NEAR(f_lmp / f_dem, 1.0, 0.05) << f_lmp << " N vs " << f_dem << " N";
    EXPECT_EQ(observed(lmp, "lid_height").step[k], std::int64_t(k));
  }
  // LAMMPS's files stay beside the store; the newest restart is the only one kept.
  EXPECT_TRUE(fs::exists(in_work("lmp.lammps/cycle2.restart")));
  EXPECT_TRUE(fs::exists(in_work("lmp.lammps/log.lammps")));
#endif
}

TEST_F(LammpsEngine, TwoRanksRunTheSameProtocol) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  granmem_ok(on_lammps(small_run("one.h5", "1")));
  std::vector<std::string> two = on_lammps(small_run("two.h5", "1"));
  two.insert(two.end(), {"--ranks", "2"});
  granmem_ok(two);
  const Trajectories one = read_trajectories(in_work("one.h5"));
  const Trajectories split = read_trajectories(in_work("two.h5"));
  ASSERT_EQ(split.frames.size(), 2u);
  // Over one cycle, forces summed in another order differ by rounding only.
  EXPECT_LT((split.frames[1].position - one.frames[1].position).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(observed(split, "wall_force").value[1], observed(one, "wall_force").value[1],
              1e-9 * observed(one, "wall_force").value[1]);
#endif
}

TEST_F(LammpsEngine, WhatLammpsCannotRunIsRefusedBeforeAnyWork) {
  auto with = [](std::vector<std::string> args, std::vector<std::string> more) {
    args.insert(args.end(), {"--engine", "lammps"});
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  expect_clean_failure(with(small_run("p.h5", "1"), {"--polydispersity", "0.1"}),
                       {"--engine lammps", "one size", "--polydispersity 0"});
  expect_clean_failure(with(small_run("p.h5", "1"), {"--lid-pressure", "0"}),
                       {"--engine lammps", "lid"});
  expect_clean_failure(with(small_run("p.h5", "1"), {"--full-compression", "yes"}),
                       {"--engine lammps", "--full-compression", "--engine granmem"});
  expect_clean_failure(with(small_run("p.h5", "1"), {"--ranks", "0"}), {"--ranks 0", "1 or more"});
  expect_clean_failure(with(small_run("p.h5", "1"), {"--lammps", "no-such-lmp"}),
                       {"--lammps 'no-such-lmp'", "no such program", "apt-get install lammps"});
  std::vector<std::string> other = small_run("p.h5", "1");
  other.insert(other.end(), {"--engine", "gromacs"});
  expect_clean_failure(other, {"--engine gromacs", "granmem or lammps"});
  EXPECT_FALSE(fs::exists(in_work("p.checkpoint.h5")));  // no deposit was made
}

}  // namespace
}  // namespace granmem
