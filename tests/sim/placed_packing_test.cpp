// A packing placed where a frame has its grains (the twin started from an experiment's own
// packing): the frame read back in metres, the grains a frame misses taken from a later
// one (once: not a track the linker broke), each replica's jitter, and a packing at rest placed
// again with no contact history settling where it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/placed_packing.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class PlacedPacking : public testing::TempDirTest {
 protected:
  // 300 grains under the paper's pressure (436 Pa on 3 x 3 cm), two cycles written.
  void SetUp() override {
    TempDirTest::SetUp();
    pour.grains = 300;
    pour.box_side = 0.03;
    pour.lid_mass = 436 * 0.03 * 0.03 / 9.81;
    pour.seed = 5;
    Simulation sim = deposit(pour, physics);
    poured = sim.grains();
    CyclicOptions c;
    c.drive.amplitude = 3e-4;
    c.drive.period = 400 * physics.dt;
    c.cycles = 2;
    c.out = path("run.h5");
    ProtocolState state;
    run_cycles(sim, c, state);
  }
  DepositOptions pour;
  PhysicsOptions physics;
  Grains poured;
};

// The distance from each grain of `a` to the nearest of `b`, in m, sorted.
std::vector<double> nearest_distances(const Grains& a, const Grains& b) {
  std::vector<double> distances;
  for (const Eigen::Vector3d& x : a.x) {
    double best = INFINITY;
    for (const Eigen::Vector3d& y : b.x)
      best = std::min(best, (x - y).norm());
    distances.push_back(best);
  }
  std::sort(distances.begin(), distances.end());
  return distances;
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[std::min(sorted.size() - 1, std::size_t(q * double(sorted.size())))];
}

TEST_F(PlacedPacking, AFramesGrainsArePlacedWhereItHasThem) {
  // The run as a tracked store would hold it: in mm, the container's corner off the origin.
  Trajectories t = read_trajectories(path("run.h5"));
  const Eigen::Vector3d corner(1.5, -2.0, 0.25);  // mm
  t.header.length_unit = "mm";
  t.header.box = Box{corner, Eigen::Vector3d(30, 30, 60)};
  for (Frame& f : t.frames)
    for (Eigen::Index i = 0; i < f.position.rows(); ++i)
      f.position.row(i) = f.position.row(i) * 1e3 + corner.transpose();
  write_trajectories(path("mm.h5"), t);
  const TrajectoryReader run(path("mm.h5"));
  const Grains g = grains_of_frame(run, 0, pour, physics);
  ASSERT_EQ(g.size(), 300u);
  EXPECT_LT(nearest_distances(g, poured).back(), 1e-12);
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(g.radius[i], pour.radius);
    for (std::size_t j = 0; j < poured.size(); ++j) {
      if (poured.id[j] != g.id[i]) continue;
      EXPECT_NEAR((g.x[i] - poured.x[j]).norm(), 0, 1e-12);
      EXPECT_NEAR(std::abs(g.q[i].dot(poured.q[j])), 1, 1e-12);  // the same rotation
    }
  }
  EXPECT_THROW(grains_of_frame(run, 3, pour, physics), Error);
}

TEST_F(PlacedPacking, AGrainTheFrameMissesIsTakenFromTheNextThatHasIt) {
  Trajectories t = read_trajectories(path("run.h5"));
  for (int k : {0, 1}) {
    t.frames[std::size_t(k)].position.row(7).setConstant(NAN);
    t.frames[std::size_t(k)].orientation.row(7).setConstant(NAN);
  }
  t.frames[0].position.row(9).setConstant(NAN);
  for (Frame& f : t.frames)
    f.position.row(11).setConstant(NAN);  // never seen: left out
  write_trajectories(path("holes.h5"), t);
  const TrajectoryReader run(path("holes.h5"));
  const Grains g = grains_of_frame(run, 0, pour, physics);
  ASSERT_EQ(g.size(), 299u);
  auto placed = [&](std::int64_t id) {
    for (std::size_t i = 0; i < g.size(); ++i)
      if (g.id[i] == id) return Eigen::Vector3d(g.x[i]);
    return Eigen::Vector3d(Eigen::Vector3d::Constant(NAN));
  };
  const auto id7 = t.header.id[7], id9 = t.header.id[9];
  EXPECT_EQ(placed(id7), t.frames[2].position.row(7).transpose());
  EXPECT_EQ(placed(id9), t.frames[1].position.row(9).transpose());
  // Its orientation from the same frame as its position.
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (g.id[i] != id7) continue;
    const auto q = t.frames[2].orientation.row(7);
    EXPECT_NEAR(std::abs(g.q[i].dot(Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized())), 1,
                1e-12);
  }
}

TEST_F(PlacedPacking, ATrackTheLinkerBrokeIsNotPlacedTwice) {
  // Grain 5's track ends at frame 0 and grain 11's starts at frame 1 where grain 5 has moved
  // by 0.7 d: the same grain, as a linker that lost it between scans far apart leaves it.
  // Placed once, where frame 0 has it.
  Trajectories t = read_trajectories(path("run.h5"));
  t.frames[0].position.row(11).setConstant(NAN);
  for (std::size_t k : {1, 2}) {
    t.frames[k].position.row(11) =
        t.frames[k].position.row(5) + Eigen::RowVector3d(1.4 * pour.radius, 0, 0);
    t.frames[k].position.row(5).setConstant(NAN);
  }
  write_trajectories(path("broken.h5"), t);
  const Grains g = grains_of_frame(TrajectoryReader(path("broken.h5")), 0, pour, physics);
  ASSERT_EQ(g.size(), 299u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_NE(g.id[i], t.header.id[11]);
    if (g.id[i] == t.header.id[5]) {
      EXPECT_EQ(g.x[i], t.frames[0].position.row(5).transpose());
    }
  }
}

TEST_F(PlacedPacking, NoMoreGrainsAreTakenFromLaterFramesThanTheFrameLacks) {
  // Grain 11's track starts at frame 1, 0.9 d above the top grain (that grain moved further
  // than a broken track's 0.75 d between scans many cycles apart); grain 7, which the scan
  // of frame 0 missed, is at frame 1 where its neighbours leave it a hole. A packing of 299
  // grains: frame 0 lacks one, grain 7, and takes only it (the farthest from the frame's
  // grains); of 300: both; of 298 (frame 0 holds them all): none.
  Trajectories t = read_trajectories(path("run.h5"));
  Eigen::Index top = 0;
  t.frames[0].position.col(2).maxCoeff(&top);
  ASSERT_NE(top, 11);
  ASSERT_NE(top, 7);
  t.frames[0].position.row(7).setConstant(NAN);
  t.frames[0].position.row(11).setConstant(NAN);
  for (std::size_t k : {1, 2}) {
    t.frames[k].position.row(11) =
        t.frames[0].position.row(top) + Eigen::RowVector3d(0, 0, 1.8 * pour.radius);
  }
  write_trajectories(path("far.h5"), t);
  const TrajectoryReader run(path("far.h5"));
  auto ids = [&](std::int64_t grains) {
    DepositOptions packing = pour;
    packing.grains = grains;
    std::vector<std::int64_t> id = grains_of_frame(run, 0, packing, physics).id;
    std::sort(id.begin(), id.end());
    return id;
  };
  auto has = [](const std::vector<std::int64_t>& id, std::int64_t one) {
    return std::binary_search(id.begin(), id.end(), one);
  };
  const std::int64_t id7 = t.header.id[7], id11 = t.header.id[11];
  const auto of299 = ids(299), of300 = ids(300), of298 = ids(298);
  EXPECT_EQ(of299.size(), 299u);
  EXPECT_TRUE(has(of299, id7));
  EXPECT_FALSE(has(of299, id11));
  EXPECT_EQ(of300.size(), 300u);
  EXPECT_EQ(of298.size(), 298u);
  EXPECT_FALSE(has(of298, id7));
}

TEST_F(PlacedPacking, EachReplicaIsJitteredByItsRmsAndStaysInTheBox) {
  const TrajectoryReader run(path("run.h5"));
  const Grains g = grains_of_frame(run, 0, pour, physics);
  const double jitter = 1e-4;
  const Grains a = jittered(g, jitter, 1, pour), b = jittered(g, jitter, 2, pour);
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d d = a.x[i] - g.x[i];
    EXPECT_GE(a.x[i].minCoeff(), a.radius[i] * (1 - 1e-12));
    EXPECT_LE(std::max(a.x[i].x(), a.x[i].y()), pour.box_side - a.radius[i] * (1 - 1e-12));
    if (d.norm() == 0) continue;
    sum += d.squaredNorm();
    n += 3;
    EXPECT_NE(a.x[i], b.x[i]);
  }
  // A grain against a wall is kept inside; the others moved by draws of RMS jitter: 900
  // draws measure it within ~5 % (3 standard errors of an RMS of 900 normals: 7 %).
  ASSERT_GT(n, 600u);
  EXPECT_NEAR(std::sqrt(sum / double(n)), jitter, 0.07 * jitter);
}

// A frame moved by a scan's locating error: each axis by its own RMS (larger along z), and
// a jitter alike on every axis is the same draws as the scalar one.
TEST_F(PlacedPacking, AScansErrorMovesEachAxisByItsOwnRms) {
  const TrajectoryReader run(path("run.h5"));
  const Grains g = grains_of_frame(run, 0, pour, physics);
  const Eigen::Vector3d error(5e-5, 5e-5, 1e-4);
  const Grains moved = jittered(g, error, 3, pour);
  Eigen::Array3d sum = Eigen::Array3d::Zero();
  std::size_t n = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d d = moved.x[i] - g.x[i];
    const double clear = g.radius[i] + 10 * error.maxCoeff();
    if (g.x[i].minCoeff() < clear || std::max(g.x[i].x(), g.x[i].y()) > pour.box_side - clear)
      continue;  // grains against a wall may be kept inside
    sum += d.array().square();
    ++n;
  }
  ASSERT_GT(n, 100u);
  // An RMS of n normals is within 3/sqrt(2 n) of its sigma, three standard errors (18 % at
  // the 144 grains clear of the walls here).
  const Eigen::Array3d rms = (sum / double(n)).sqrt();
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(rms[a], error[a], 3 / std::sqrt(2.0 * double(n)) * error[a]) << "axis " << a;
  const Grains alike = jittered(g, Eigen::Vector3d::Constant(1e-4), 1, pour);
  const Grains scalar = jittered(g, 1e-4, 1, pour);
  for (std::size_t i = 0; i < g.size(); ++i)
    EXPECT_EQ(alike.x[i], scalar.x[i]);
}

TEST_F(PlacedPacking, APackingAtRestPlacedAgainSettlesWhereItWas) {
  // The deposited packing (frame 0) placed with no contact forces and the lid on it at once:
  // the springs of its contacts build again within microns of slip (a contact's load over
  // k_t), so it settles where it was. (Settled first without the lid, as a pour is, it
  // moved by 0.077 d RMS and its lid came 0.04 d lower.) A few unloaded grains may still
  // drop into a gap below them (up to 0.2 d measured), so the bulk is what is asserted.
  const TrajectoryReader run(path("run.h5"));
  DepositSummary after;
  Simulation again = settled_packing(grains_of_frame(run, 0, pour, physics), pour, physics,
                                     GrainPlacement::at_rest, &after);
  const double d = 2 * pour.radius;
  const std::vector<double> moved = nearest_distances(again.grains(), poured);
  // Measured over pour seeds 1-9 and two compilers: median 0.0007-0.0029 d, 90th
  // percentile 0.0023-0.0108 d.
  EXPECT_LT(quantile(moved, 0.5), 0.005 * d);
  EXPECT_LT(quantile(moved, 0.9), 0.02 * d);
  const double lid = run.observables().at("lid_height").value.front();
  EXPECT_NEAR(after.lid_height, lid, 0.01 * d);  // measured 0.0027 d lower
}

TEST_F(PlacedPacking, APackingPlacedFromAScansPositionsKeepsItsHeight) {
  // The deposited packing's frame with a scan's locating errors (0.001 d across the slices,
  // 0.002 d along z, as the default render's scans err on 5 mm grains), three draws: their
  // overlaps exceed the contacts' own, and released under the pouring drag they tap the
  // packing denser than its frame; at the placed packing's drag it keeps its frame's height.
  const TrajectoryReader run(path("run.h5"));
  const double d = 2 * pour.radius;
  const double lid = run.observables().at("lid_height").value.front();
  DepositOptions pouring_drag = pour;
  pouring_drag.placed_settling_damping = pour.settling_damping;
  for (std::uint64_t seed : {11, 12, 13}) {
    Grains scanned = grains_of_frame(run, 0, pour, physics);
    Random random(seed);
    for (Eigen::Vector3d& x : scanned.x) {
      const double ez = random.normal(), ey = random.normal(), ex = random.normal();
      x += d * Eigen::Vector3d(0.001 * ex, 0.001 * ey, 0.002 * ez);
      x.z() = std::max(x.z(), pour.radius);
    }
    DepositSummary placed, tapped;
    settled_packing(scanned, pour, physics, GrainPlacement::at_rest, &placed);
    settled_packing(scanned, pouring_drag, physics, GrainPlacement::at_rest, &tapped);
    EXPECT_NEAR(placed.lid_height, lid, 0.002 * d) << "draw " << seed;
    EXPECT_LT(tapped.lid_height, lid - 0.004 * d) << "draw " << seed;
  }
}

}  // namespace
}  // namespace granmem
