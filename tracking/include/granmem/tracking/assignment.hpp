#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace granmem {

// A sparse bipartite cost graph: row r may take column columns[k] at cost costs[k] for
// k in [offsets[r], offsets[r + 1]). Costs must be finite and non-negative.
struct SparseCosts {
  std::size_t rows = 0, cols = 0;
  std::vector<std::size_t> offsets{0};  // rows + 1 entries
  std::vector<std::uint32_t> columns;
  std::vector<double> costs;
};

// The exact minimum-cost one-to-one assignment with the option of leaving a row
// unassigned at `unassigned_cost`: minimises  sum(cost of the pairs taken) +
// unassigned_cost * (rows left out), each column taken at most once. Returns, per row, its
// column or -1. Solved by successive shortest augmenting paths (Dijkstra on reduced costs,
// the sparse form of the Hungarian / Jonker-Volgenant method): each row gets a private
// "unassigned" column, so an augmenting path always exists, and the search from a row
// stops at the first free column it reaches, so it only ever explores the part of the
// graph that actually competes for the same columns. The result is optimal over the whole
// graph, and hence over each connected group of candidates.
std::vector<std::int64_t> min_cost_assignment(const SparseCosts& graph, double unassigned_cost);

}  // namespace granmem
