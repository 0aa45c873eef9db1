// The sparse minimum-cost assignment against brute force on small random graphs, and its
// hand-worked cases.

#include "granmem/tracking/assignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

SparseCosts graph_of(std::size_t rows, std::size_t cols,
                     const std::vector<std::vector<std::pair<std::uint32_t, double>>>& edges) {
  SparseCosts g;
  g.rows = rows;
  g.cols = cols;
  for (const auto& row : edges) {
    for (const auto& [c, cost] : row) {
      g.columns.push_back(c);
      g.costs.push_back(cost);
    }
    g.offsets.push_back(g.columns.size());
  }
  return g;
}

// The cost of an assignment; infinity if it takes a column twice or a pair not in the graph.
double total_cost(const SparseCosts& g, const std::vector<std::int64_t>& col, double unassigned) {
  double total = 0;
  std::set<std::int64_t> taken;
  for (std::size_t r = 0; r < g.rows; ++r) {
    if (col[r] < 0) {
      total += unassigned;
      continue;
    }
    if (!taken.insert(col[r]).second) return std::numeric_limits<double>::infinity();
    bool found = false;
    for (std::size_t k = g.offsets[r]; k < g.offsets[r + 1] && !found; ++k) {
      if (g.columns[k] == std::uint32_t(col[r])) {
        total += g.costs[k];
        found = true;
      }
    }
    if (!found) return std::numeric_limits<double>::infinity();
  }
  return total;
}

// The optimum by trying every choice of every row.
double brute_force(const SparseCosts& g, double unassigned) {
  double best = std::numeric_limits<double>::infinity();
  std::vector<char> taken(g.cols, 0);
  std::function<void(std::size_t, double)> go = [&](std::size_t r, double sum) {
    if (sum >= best) return;
    if (r == g.rows) {
      best = sum;
      return;
    }
    go(r + 1, sum + unassigned);
    for (std::size_t k = g.offsets[r]; k < g.offsets[r + 1]; ++k) {
      const std::uint32_t c = g.columns[k];
      if (taken[c]) continue;
      taken[c] = 1;
      go(r + 1, sum + g.costs[k]);
      taken[c] = 0;
    }
  };
  go(0, 0.0);
  return best;
}

TEST(Assignment, HandWorkedChainTakesTheGlobalOptimum) {
  // Greedy would give row 0 its cheapest column 0 (cost 1), leaving row 1 only column 1
  // at 10: total 11. The optimum is 0->1 (2) and 1->0 (2): total 4.
  const SparseCosts g = graph_of(2, 2, {{{0, 1.0}, {1, 2.0}}, {{0, 2.0}, {1, 10.0}}});
  const std::vector<std::int64_t> a = min_cost_assignment(g, 100.0);
  EXPECT_EQ(a, (std::vector<std::int64_t>{1, 0}));
  EXPECT_DOUBLE_EQ(total_cost(g, a, 100.0), 4.0);
}

TEST(Assignment, LeavesARowOutWhenThatIsCheaper) {
  // Both rows want column 0; the second choice of row 1 (5) costs more than leaving it out (3).
  const SparseCosts g = graph_of(2, 1, {{{0, 1.0}}, {{0, 1.5}}});
  const std::vector<std::int64_t> a = min_cost_assignment(g, 3.0);
  EXPECT_DOUBLE_EQ(total_cost(g, a, 3.0), 4.0);
  // A pair dearer than leaving the row out is never taken.
  const SparseCosts dear = graph_of(1, 1, {{{0, 5.0}}});
  EXPECT_EQ(min_cost_assignment(dear, 3.0), (std::vector<std::int64_t>{-1}));
}

TEST(Assignment, EmptyGraphs) {
  EXPECT_TRUE(min_cost_assignment(SparseCosts{}, 1.0).empty());
  const SparseCosts no_edges = graph_of(3, 0, {{}, {}, {}});
  EXPECT_EQ(min_cost_assignment(no_edges, 1.0), (std::vector<std::int64_t>{-1, -1, -1}));
}

TEST(Assignment, MatchesBruteForceOnRandomGraphs) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> size(1, 7);
  std::uniform_real_distribution<double> uniform(0, 1);
  int with_left_out = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::size_t rows = std::size_t(size(rng)), cols = std::size_t(size(rng));
    const double density = 0.2 + 0.8 * uniform(rng);
    std::vector<std::vector<std::pair<std::uint32_t, double>>> edges(rows);
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::uint32_t c = 0; c < cols; ++c) {
        // Integer costs in some trials, to have ties.
        const double cost = trial % 2 ? std::floor(4 * uniform(rng)) : uniform(rng);
        if (uniform(rng) < density) edges[r].emplace_back(c, cost);
      }
    }
    const SparseCosts g = graph_of(rows, cols, edges);
    const double unassigned = trial % 3 == 0 ? 10.0 : 0.1 + uniform(rng);
    const std::vector<std::int64_t> a = min_cost_assignment(g, unassigned);
    ASSERT_EQ(a.size(), rows);
    const double got = total_cost(g, a, unassigned), best = brute_force(g, unassigned);
    ASSERT_NEAR(got, best, 1e-12) << "trial " << trial;
    for (std::int64_t c : a)
      with_left_out += c < 0;
  }
  EXPECT_GT(with_left_out, 1000);  // the option of leaving rows out was exercised
}

TEST(Assignment, RejectsMalformedGraphs) {
  SparseCosts g = graph_of(1, 1, {{{0, 1.0}}});
  EXPECT_THROW(min_cost_assignment(g, -1.0), Error);
  EXPECT_THROW(min_cost_assignment(g, std::nan("")), Error);
  SparseCosts negative = g;
  negative.costs[0] = -1;
  EXPECT_THROW(min_cost_assignment(negative, 1.0), Error);
  SparseCosts out_of_range = g;
  out_of_range.columns[0] = 1;
  EXPECT_THROW(min_cost_assignment(out_of_range, 1.0), Error);
  SparseCosts short_offsets = g;
  short_offsets.offsets = {0};
  EXPECT_THROW(min_cost_assignment(short_offsets, 1.0), Error);
}

}  // namespace
}  // namespace granmem
