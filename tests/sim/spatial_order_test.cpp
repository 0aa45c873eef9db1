// Relabelling a packing in spatial order (in_spatial_order): every grain, spring and force
// carried over, neighbours given near ids, and the continuation the same physics.
#include "granmem/sim/spatial_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "granmem/core/error.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kRadius;
using testing::same_bits;

// A dense frictional cluster squeezed by a box and a lid, every friction mode at work, its
// ids shuffled (so relabelling swaps the owners of many pairs), run until it has springs.
Simulation sheared_cluster() {
  Grains g = testing::lattice_cluster(5, 5, 5, 0.995, 3);
  std::mt19937 random(8);
  std::shuffle(g.id.begin(), g.id.end(), random);
  PhysicsOptions p;
  p.contact.mu_r = 0.05;
  p.contact.mu_t = 0.05;
  Container c;
  const double extent = 2 * kRadius * 0.995 * 4 + 2 * kRadius;
  c.size = {extent - 1e-5, extent - 1e-5};
  c.lid.present = true;
  c.lid.mass = 0.5;
  c.lid.z = extent - 2e-5;
  Simulation sim(g, c, p);
  sim.run(100);
  return sim;
}

// Index in `b` of each grain of `a`, matched by position (bit for bit).
std::vector<std::size_t> match_by_position(const Grains& a, const Grains& b) {
  std::map<std::array<double, 3>, std::size_t> where;
  for (std::size_t i = 0; i < b.size(); ++i)
    where[{b.x[i].x(), b.x[i].y(), b.x[i].z()}] = i;
  std::vector<std::size_t> out;
  for (const auto& x : a.x)
    out.push_back(where.at({x.x(), x.y(), x.z()}));
  return out;
}

TEST(SpatialOrder, NeighboursGetNearIdsAndEveryGrainAndSpringIsCarried) {
  const Simulation a = sheared_cluster();
  const Simulation b = in_spatial_order(a);
  const Grains &ga = a.grains(), &gb = b.grains();
  ASSERT_EQ(gb.size(), ga.size());
  const double cell = 2 * kRadius * 0.99;  // below the smallest mean diameter
  for (std::size_t i = 0; i < gb.size(); ++i) {
    EXPECT_EQ(gb.id[i], std::int64_t(i));
    if (i > 0) {
      EXPECT_GE(std::floor(gb.x[i].z() / cell) + 1, std::floor(gb.x[i - 1].z() / cell));
    }
  }
  const std::vector<std::size_t> to_b = match_by_position(ga, gb);
  std::map<std::int64_t, std::int64_t> new_id;
  for (std::size_t i = 0; i < ga.size(); ++i) {
    const std::size_t k = to_b[i];
    new_id[ga.id[i]] = gb.id[k];
    EXPECT_TRUE(same_bits(ga.v[i], gb.v[k]) && same_bits(ga.w[i], gb.w[k]) &&
                same_bits(ga.q[i], gb.q[k]) && same_bits(ga.force[i], gb.force[k]) &&
                same_bits(ga.torque[i], gb.torque[k]) && same_bits(ga.radius[i], gb.radius[k]))
        << "grain " << ga.id[i];
    for (int w = 0; w < kWallCount; ++w) {
      EXPECT_TRUE(same_bits(a.wall_histories()[i][w].slide, b.wall_histories()[k][w].slide));
    }
  }
  std::map<std::pair<std::int64_t, std::int64_t>, ContactHistory> springs;
  for (const auto& p : b.pair_histories())
    springs[{p.id_a, p.id_b}] = p.history;
  const auto pairs = a.pair_histories();
  ASSERT_GT(pairs.size(), 100u);
  ASSERT_EQ(springs.size(), pairs.size());
  int swapped = 0;
  for (const auto& p : pairs) {
    const std::int64_t i = new_id.at(p.id_a), j = new_id.at(p.id_b);
    const bool swap = i > j;
    swapped += swap;
    const ContactHistory& h = springs.at({std::min(i, j), std::max(i, j)});
    EXPECT_TRUE(same_bits(h.slide, swap ? Eigen::Vector3d(-p.history.slide) : p.history.slide));
    EXPECT_TRUE(same_bits(h.roll, p.history.roll));
    EXPECT_TRUE(same_bits(h.twist, p.history.twist));
  }
  EXPECT_GT(swapped, 20);
}

// Only the order of each grain's force sum changes: the two runs part by rounding alone.
// A wrong spring (a sliding spring not turned with its pair) moves grains by microns.
TEST(SpatialOrder, TheContinuationIsTheSamePhysics) {
  Simulation a = sheared_cluster();
  Simulation b = in_spatial_order(a);
  const std::vector<std::size_t> to_b = match_by_position(a.grains(), b.grains());
  a.run(200);
  b.run(200);
  double worst = 0, moved = 0;
  for (std::size_t i = 0; i < a.grains().size(); ++i) {
    worst = std::max(worst, (a.grains().x[i] - b.grains().x[to_b[i]]).norm());
    moved = std::max(moved, (a.grains().v[i]).norm() * 200 * a.physics().dt);
  }
  RecordProperty("worst_position_difference_m", testing::number(worst));
  EXPECT_GT(moved, 1e-6);  // the grains do move
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(a.contact_count(), b.contact_count());
}

// A grain without a finite position (a blown-up step, a damaged checkpoint) has no place
// in the neighbour list's cells, nor in a spatial order: the simulation is refused.
TEST(SpatialOrder, AGrainWithoutAFinitePositionIsRefused) {
  Grains g = testing::lattice_cluster(2, 2, 2, 1.2, 1);
  g.x[3].y() = std::nan("");
  try {
    const Simulation sim(g, testing::wide_box(1.0), PhysicsOptions{});
    FAIL() << "accepted a NaN position";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("grain 33 has no finite position"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace granmem
