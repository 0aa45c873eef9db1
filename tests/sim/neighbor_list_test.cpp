// The Verlet list against brute force: every pair closer than r_i + r_j + skin listed exactly
// once, under the grain of smaller id, each grain's pairs sorted by the partner's id, the
// incoming lists their exact transpose sorted by the owner's id; carry() keeps the values of
// pairs present before and after; moved_too_far() trips at half the skin.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <utility>

#include "granmem/sim/neighbor_list.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kDensity;
using testing::kRadius;

// `n` grains of radii kRadius +-30% at random in a box of side `side` (overlaps allowed),
// with scattered ids that do not follow the memory order. `flat`: all at one height.
Grains random_grains(std::size_t n, double side, unsigned seed, bool flat = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::int64_t> ids(n);
  for (std::size_t i = 0; i < n; ++i)
    ids[i] = std::int64_t(7 * i * i + 1000);
  std::shuffle(ids.begin(), ids.end(), rng);
  Grains g;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x(side * u(rng), side * u(rng), flat ? 0.01 : side * u(rng));
    g.add(ids[i], x, kRadius * (0.7 + 0.6 * u(rng)), kDensity);
  }
  return g;
}

using Pair = std::pair<std::int64_t, std::int64_t>;  // (smaller id, larger id)

std::set<Pair> brute_force_pairs(const Grains& g, double skin) {
  std::set<Pair> out;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (std::size_t j = i + 1; j < g.size(); ++j) {
      const double reach = g.radius[i] + g.radius[j] + skin;
      if ((g.x[i] - g.x[j]).squaredNorm() < reach * reach) {
        out.insert({std::min(g.id[i], g.id[j]), std::max(g.id[i], g.id[j])});
      }
    }
  }
  return out;
}

// Checks every structural promise of the list; returns its pairs by id.
std::set<Pair> checked_pairs(const NeighborList& list, const Grains& g) {
  std::set<Pair> pairs;
  const auto& partner = list.partner();
  const auto& owner = list.owner();
  EXPECT_EQ(partner.size(), list.pair_count());
  EXPECT_EQ(owner.size(), list.pair_count());
  EXPECT_EQ(list.begin(0), 0u);
  EXPECT_EQ(list.end(g.size() - 1), list.pair_count());
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_LE(list.begin(i), list.end(i));
    for (std::uint32_t k = list.begin(i); k < list.end(i); ++k) {
      const std::uint32_t j = partner[k];
      EXPECT_EQ(owner[k], i);
      EXPECT_LT(g.id[i], g.id[j]) << "the owner must have the smaller id";
      if (k > list.begin(i)) {
        EXPECT_LT(g.id[partner[k - 1]], g.id[j]) << "partners not sorted by id";
      }
      EXPECT_TRUE(pairs.insert({g.id[i], g.id[j]}).second) << "pair listed twice";
    }
  }
  // Incoming: exactly the pairs whose partner is i, sorted by the owner's id.
  std::vector<std::uint32_t> seen(list.pair_count(), 0);
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_LE(list.incoming_begin(i), list.incoming_end(i));
    for (std::uint32_t s = list.incoming_begin(i); s < list.incoming_end(i); ++s) {
      const std::uint32_t k = list.incoming()[s];
      EXPECT_LT(k, list.pair_count());
      if (k >= list.pair_count()) return pairs;
      EXPECT_EQ(partner[k], i);
      ++seen[k];
      if (s > list.incoming_begin(i)) {
        EXPECT_LT(g.id[owner[list.incoming()[s - 1]]], g.id[owner[k]]) << "incoming not sorted";
      }
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](std::uint32_t c) { return c == 1; }))
      << "every pair must be incoming to its partner exactly once";
  return pairs;
}

TEST(NeighborList, ListsExactlyThePairsInReachAsBruteForceDoes) {
  const double skin = 5e-4;
  for (unsigned seed : {1u, 2u, 3u}) {
    // Dense (many pairs per grain) and dilute.
    for (double side : {0.02, 0.08}) {
      const Grains g = random_grains(400, side, seed);
      NeighborList list(skin);
      list.build(g);
      const std::set<Pair> expected = brute_force_pairs(g, skin);
      EXPECT_EQ(checked_pairs(list, g), expected) << "seed " << seed << " side " << side;
      EXPECT_FALSE(expected.empty());
    }
  }
}

TEST(NeighborList, FlatLayersAndTinySetsAreHandled) {
  const double skin = 5e-4;
  const Grains flat = random_grains(200, 0.03, 4, true);
  NeighborList list(skin);
  list.build(flat);
  EXPECT_EQ(checked_pairs(list, flat), brute_force_pairs(flat, skin));

  Grains one;
  one.add(5, {0.1, 0.1, 0.1}, kRadius, kDensity);
  list.build(one);
  EXPECT_EQ(list.pair_count(), 0u);
  EXPECT_EQ(list.incoming_begin(0), list.incoming_end(0));

  // Two grains at the same place, and two just out of reach.
  Grains pairs;
  pairs.add(9, {0.1, 0.1, 0.1}, kRadius, kDensity);
  pairs.add(4, {0.1, 0.1, 0.1}, kRadius, kDensity);
  pairs.add(2, {0.2, 0.1, 0.1}, kRadius, kDensity);
  pairs.add(1, {0.2 + 2 * kRadius + skin * 1.0001, 0.1, 0.1}, kRadius, kDensity);
  list.build(pairs);
  EXPECT_EQ(checked_pairs(list, pairs), (std::set<Pair>{{4, 9}}));
  EXPECT_EQ(list.begin(1), 0u);  // grain index 1 (id 4) owns it
  EXPECT_EQ(list.end(1), 1u);
}

TEST(NeighborList, CarryKeepsTheValuesOfPairsPresentInBothLists) {
  const double skin = 5e-4;
  Grains g = random_grains(300, 0.025, 5);
  NeighborList before(skin);
  before.build(g);
  // A value per pair that names it: the ids of its grains.
  auto name = [&](const NeighborList& l, std::uint32_t k) {
    return double(g.id[l.owner()[k]]) * 1e6 + double(g.id[l.partner()[k]]);
  };
  std::vector<double> values(before.pair_count());
  for (std::uint32_t k = 0; k < before.pair_count(); ++k)
    values[k] = name(before, k);
  std::set<Pair> old_pairs = checked_pairs(before, g);

  // Grains move: some pairs part, others form.
  std::mt19937_64 rng(6);
  std::normal_distribution<double> step(0, 1e-3);
  for (auto& x : g.x)
    x += Eigen::Vector3d(step(rng), step(rng), step(rng));
  NeighborList after(skin);
  after.build(g);
  const std::set<Pair> new_pairs = checked_pairs(after, g);
  const std::vector<double> carried = after.carry(before, values, g.id, -1.0);
  ASSERT_EQ(carried.size(), after.pair_count());
  std::size_t kept = 0, fresh = 0;
  for (std::uint32_t k = 0; k < after.pair_count(); ++k) {
    const Pair p{g.id[after.owner()[k]], g.id[after.partner()[k]]};
    if (old_pairs.count(p)) {
      EXPECT_EQ(carried[k], name(after, k)) << "pair " << p.first << "-" << p.second;
      ++kept;
    } else {
      EXPECT_EQ(carried[k], -1.0) << "new pair " << p.first << "-" << p.second;
      ++fresh;
    }
  }
  EXPECT_GT(kept, 100u);
  EXPECT_GT(fresh, 10u);
  EXPECT_LT(new_pairs.size(), old_pairs.size() + fresh);  // some pairs parted too

  // Another set of grains: nothing carries.
  Grains fewer = random_grains(200, 0.025, 7);
  NeighborList other(skin);
  other.build(fewer);
  const std::vector<double> none = other.carry(before, values, fewer.id, -1.0);
  EXPECT_TRUE(std::all_of(none.begin(), none.end(), [](double v) { return v == -1.0; }));
}

TEST(NeighborList, IsStaleOnceAGrainHasMovedMoreThanHalfTheSkin) {
  const double skin = 4e-4;
  Grains g = random_grains(50, 0.03, 8);
  NeighborList list(skin);
  EXPECT_TRUE(list.moved_too_far(g.x[0], 0)) << "never built";
  list.build(g);
  EXPECT_FALSE(list.moved_too_far(g.x[17], 17));
  g.x[17] += Eigen::Vector3d(0, 0.49 * skin, 0);
  EXPECT_FALSE(list.moved_too_far(g.x[17], 17));
  g.x[17] += Eigen::Vector3d(0, 0.02 * skin, 0);
  EXPECT_TRUE(list.moved_too_far(g.x[17], 17));
  list.build(g);
  EXPECT_FALSE(list.moved_too_far(g.x[17], 17));
}

}  // namespace
}  // namespace granmem
