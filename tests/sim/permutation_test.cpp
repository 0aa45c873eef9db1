// Determinism of the force sums. Each grain's forces are summed over its contacts in the
// order of the partners' ids, each pair evaluated by its owner (the smaller id), so a grain's
// results depend on the grains alone: the same grains in another memory order, with ids
// relabelled in the same order, on 1 or 2 threads, with another neighbour skin (another
// rebuild schedule), or stepped in runs of other lengths (within a run the next step's
// first half is done in the force pass) must give the same forces, torques and motion per
// grain, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <unordered_map>

#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kRadius;
using testing::same_bits;

constexpr int kSide = 4;
constexpr double kSpacing = 0.995;  // overlapping: a dense, touching, exploding cluster

// Grains `g` in the order `order` (new index k holds old grain order[k]).
Grains reordered(const Grains& g, const std::vector<std::size_t>& order) {
  Grains out;
  for (std::size_t k : order) {
    out.id.push_back(g.id[k]);
    out.radius.push_back(g.radius[k]);
    out.mass.push_back(g.mass[k]);
    out.inv_mass.push_back(g.inv_mass[k]);
    out.inv_inertia.push_back(g.inv_inertia[k]);
    out.x.push_back(g.x[k]);
    out.v.push_back(g.v[k]);
    out.w.push_back(g.w[k]);
    out.q.push_back(g.q[k]);
    out.force.push_back(g.force[k]);
    out.torque.push_back(g.torque[k]);
  }
  return out;
}

// The cluster in a box that squeezes it, under gravity, with (or without) a lid resting on
// its top layer.
Simulation cluster(const Grains& g, bool lid, double skin = PhysicsOptions{}.skin) {
  PhysicsOptions p;
  p.skin = skin;
  p.contact.mu_r = 0.05;  // every mode at work
  p.contact.mu_t = 0.05;
  Container c;
  const double extent = 2 * kRadius * kSpacing * (kSide - 1) + 2 * kRadius;
  c.size = {extent - 1e-5, extent - 1e-5};
  c.lid.present = lid;
  c.lid.mass = 0.5;  // heavy enough to stay on the cluster
  c.lid.z = extent - 2e-5;
  return Simulation(g, c, p);
}

// Per-grain state of `a` and `b` equal bit for bit, grains matched by id.
::testing::AssertionResult same_per_grain(const Simulation& a, const Simulation& b) {
  const Grains &ga = a.grains(), &gb = b.grains();
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < gb.size(); ++i)
    index[gb.id[i]] = i;
  std::vector<std::size_t> order;
  for (std::int64_t id : ga.id)
    order.push_back(index.at(id));
  return testing::same_grain_state(ga, reordered(gb, order));
}

constexpr int kSteps = 400;  // 10 ms: grains move by more than half the skin

TEST(Permutation, GrainsInAnotherOrderGiveTheSameResultsBitForBit) {
  // Unequal grains, and equal ones (whose pairs all have the same reduced mass).
  for (double polydispersity : {0.02, 0.0}) {
    SCOPED_TRACE("polydispersity " + std::to_string(polydispersity));
    const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 1, polydispersity);
    std::vector<std::size_t> order(g.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    Simulation a = cluster(g, false), b = cluster(reordered(g, order), false);
    EXPECT_TRUE(same_per_grain(a, b)) << "before the first step";
    std::size_t contacts = 0;
    for (int s = 0; s < kSteps; ++s) {
      a.step();
      b.step();
      contacts += a.contact_count();
    }
    EXPECT_GT(contacts, 50u * kSteps);
    EXPECT_TRUE(same_per_grain(a, b));
  }
}

// Ids relabelled by an increasing map keep every owner and every summation order.
TEST(Permutation, IdsRelabelledInTheSameOrderGiveTheSameResultsBitForBit) {
  const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 2);
  Grains relabelled = g;
  for (auto& id : relabelled.id)
    id = 1000003 * id - 77;
  std::vector<std::size_t> order(g.size());
  std::iota(order.begin(), order.end(), 0);
  std::reverse(order.begin(), order.end());
  Simulation a = cluster(g, false), b = cluster(reordered(relabelled, order), false);
  a.run(kSteps);
  b.run(kSteps);
  Grains back = b.grains();
  for (auto& id : back.id)
    id = (id + 77) / 1000003;
  EXPECT_TRUE(testing::same_grain_state(a.grains(), reordered(back, order)));
}

// The lid moves with the sum of the grains' loads on it: that sum, too, must not depend on the
// grains' memory order, or the lid, and every grain under it, drifts apart by rounding.
// (It did, by one ulp of the lid's force from the first step, while the loads were summed in
// memory order.)
TEST(Permutation, GrainsInAnotherOrderUnderALidGiveTheSameResultsBitForBit) {
  const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 3);
  std::vector<std::size_t> order(g.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(8));
  Simulation a = cluster(g, true), b = cluster(reordered(g, order), true);
  int lid_contacts = 0, first_difference = -1;
  for (int s = 0; s < kSteps; ++s) {
    a.step();
    b.step();
    lid_contacts += a.wall_loads().contacts[int(Wall::lid)];
    if (first_difference < 0 && !same_bits(a.container().lid.force, b.container().lid.force))
      first_difference = s;
  }
  EXPECT_GT(lid_contacts, kSteps);
  EXPECT_EQ(first_difference, -1) << "lid forces differ from step " << first_difference;
  EXPECT_TRUE(same_bits(a.container().lid.z, b.container().lid.z))
      << "lid heights differ by " << a.container().lid.z - b.container().lid.z << " m";
  EXPECT_TRUE(same_per_grain(a, b));
}

TEST(Permutation, OneTwoAndThreeThreadsGiveTheSameResultsBitForBit) {
  const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 4);
  // Three threads make shares (21, 21, 22 grains) that end inside the force pass's blocks
  // of 32, two make shares that end with them.
  for (int threads : {2, 3}) {
    Simulation a = cluster(g, true), b = cluster(g, true);
    // A small system runs on one thread by default: ask for more.
    a.set_threads(1);
    b.set_threads(threads);
    ASSERT_EQ(b.threads(), threads);
    a.run(kSteps);
    b.run(kSteps);
    EXPECT_TRUE(testing::same_grain_state(a.grains(), b.grains())) << threads << " threads";
    EXPECT_TRUE(same_bits(a.container().lid.z, b.container().lid.z));
    EXPECT_TRUE(same_bits(a.container().lid.v, b.container().lid.v));
    for (int w = 0; w < kWallCount; ++w)
      EXPECT_TRUE(same_bits(a.wall_loads().force[w], b.wall_loads().force[w])) << "wall " << w;
  }
}

// Rebuilding the neighbour list at other times (another skin) changes which far pairs are
// listed, never a force.
TEST(Permutation, AnotherNeighbourSkinGivesTheSameResultsBitForBit) {
  const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 5);
  Simulation a = cluster(g, true, 5e-4), b = cluster(g, true, 2e-4);
  a.run(kSteps);
  b.run(kSteps);
  EXPECT_TRUE(testing::same_grain_state(a.grains(), b.grains()));
  EXPECT_TRUE(same_bits(a.container().lid.z, b.container().lid.z));
}

// One run of many steps, runs of uneven lengths and single steps, with a driven wall and a
// lid, on 1 and 2 threads: the same state after each run, bit for bit.
TEST(Permutation, RunsOfAnyLengthGiveTheSameResultsAsSingleStepsBitForBit) {
  const Grains g = testing::lattice_cluster(kSide, kSide, kSide, kSpacing, 6);
  for (int threads : {1, 2}) {
    Simulation single = cluster(g, true), runs = cluster(g, true);
    single.set_threads(threads);
    runs.set_threads(threads);
    for (Simulation* sim : {&single, &runs}) {
      const double y0 = sim->container().y_wall;
      sim->set_wall_motion([y0](double t) {  // squeezes the cluster by 20 um over the test
        return std::pair<double, double>{y0 + 2e-5 * t / 0.01, 2e-5 / 0.01};
      });
    }
    int steps = 0;
    for (int length : {1, 2, 97, 3, 1, 160, 136}) {
      runs.run(length);
      for (int s = 0; s < length; ++s)
        single.step();
      steps += length;
      ASSERT_TRUE(testing::same_grain_state(single.grains(), runs.grains()))
          << threads << " threads, after " << steps << " steps";
      ASSERT_TRUE(same_bits(single.container().lid.z, runs.container().lid.z));
      ASSERT_TRUE(same_bits(single.container().lid.v, runs.container().lid.v));
      ASSERT_TRUE(same_bits(single.container().y_wall, runs.container().y_wall));
      ASSERT_EQ(single.step_count(), runs.step_count());
    }
    EXPECT_EQ(steps, kSteps);
    EXPECT_GT(runs.neighbor_builds(), 1) << "the test should cross a neighbour rebuild";
  }
}

}  // namespace
}  // namespace granmem
